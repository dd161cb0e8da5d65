"""A ROS domain of its own for a test run: a free ``ROS_DOMAIN_ID`` claimed with a lock.

``mlaunch test``, mlaunch's ``launch_test`` and its pytest plugins, and launch_testing_ros's
``EnableRmwIsolation`` claim one when the user set no ``ROS_DOMAIN_ID``, so tests run at the same
time on one machine (CI jobs, ``mlaunch test -j``, pytest-xdist) never see each other's nodes.
The claim is a lock file per id (``/tmp/mlaunch-ros-domain-<id>.lock``, held with flock while
the run lasts; the suite's own tests/ros_domain.py takes the same files), so it ends with the
process however that ends, and a crashed run leaves nothing held. Discovery is kept on the
machine (``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST``) unless the user chose a range.

Ids 1-101 go first: with DDS each domain takes ports from 7400 + 250 * id, and above 101 those
fall in Linux's ephemeral range, where another program may hold one (ROS 2's documentation says
so); 102-232 are used when the lower ones are all taken. 0, the default every unisolated ROS
program shares, is never claimed.
"""

from __future__ import annotations

import fcntl
import os
import random

TYPE_CHECKING = False  # mypy reads this as typing.TYPE_CHECKING; typing costs ~3 ms
if TYPE_CHECKING:
    from collections.abc import MutableMapping

LOCK_PATTERN = "/tmp/mlaunch-ros-domain-{}.lock"
SAFE = range(1, 102)  # ports below Linux's ephemeral range
HIGH = range(102, 233)  # the rest of what a DDS domain id may be on Linux


class DomainClaim:
    """A claimed domain id; ``release`` (or the process ending) lets it go."""

    __slots__ = ("domain", "fd")

    def __init__(self, domain: int, fd: int) -> None:
        self.domain = domain
        self.fd: int | None = fd

    def release(self) -> None:
        if self.fd is not None:
            os.close(self.fd)
            self.fd = None
            _HELD.discard(self.domain)

    def __enter__(self) -> DomainClaim:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.release()


def try_lock(path: str) -> int | None:
    """A descriptor holding ``path``'s exclusive lock, or None when another process holds it."""
    fd = os.open(path, os.O_CREAT | os.O_RDWR | os.O_CLOEXEC, 0o666)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        os.close(fd)
        return None
    return fd


def claim(pattern: str = LOCK_PATTERN) -> DomainClaim:
    """A domain no other run holds (RuntimeError when all 232 are held); ``pattern``: the lock
    files' path with ``{}`` for the id."""
    for ids in (SAFE, HIGH):
        order = list(ids)
        random.shuffle(order)  # runs starting together try different ids first
        for domain in order:
            try:
                fd = try_lock(pattern.format(domain))
            except OSError:
                continue  # a lock file another user made and we cannot open: not ours to take
            if fd is not None:
                _HELD.add(domain)
                return DomainClaim(domain, fd)
    raise RuntimeError("no free ROS_DOMAIN_ID: all of 1-232 are held by other runs")


_HELD: set[int] = set()  # the domains this process holds a claim on


def held(value: str) -> bool:
    """Whether ROS_DOMAIN_ID ``value`` is a domain this process claimed (and still holds)."""
    return value.strip().isdigit() and int(value) in _HELD


def isolate(environ: MutableMapping[str, str], pattern: str = LOCK_PATTERN) -> DomainClaim | None:
    """Claim a domain and set it in ``environ`` when the user set none; None when they did.

    Discovery stays on this machine unless ``environ`` chose a range (or the deprecated
    ROS_LOCALHOST_ONLY).
    """
    if environ.get("ROS_DOMAIN_ID", "").strip():
        return None
    found = claim(pattern)
    environ["ROS_DOMAIN_ID"] = str(found.domain)
    if "ROS_AUTOMATIC_DISCOVERY_RANGE" not in environ and "ROS_LOCALHOST_ONLY" not in environ:
        environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    return found


def describe(environ: MutableMapping[str, str], claimed: DomainClaim | None) -> str:
    """The verdict's words for the domain a run used."""
    domain = environ.get("ROS_DOMAIN_ID", "").strip() or "0"
    scope = environ.get("ROS_AUTOMATIC_DISCOVERY_RANGE", "") or "SUBNET"
    if environ.get("ROS_LOCALHOST_ONLY") == "1":
        scope = "LOCALHOST"
    if claimed is not None:
        return f"{domain} (a domain of its own, discovery {scope})"
    return f"{domain} (ROS_DOMAIN_ID set by the user, discovery {scope})"


class Isolation:
    """``isolate`` for a while: the claim and what ``environ`` held before, put back at ``end``
    (a pytest item of launch_testing's, a launch_pytest fixture's launch)."""

    KEYS = ("ROS_DOMAIN_ID", "ROS_AUTOMATIC_DISCOVERY_RANGE")

    def __init__(self, environ: MutableMapping[str, str] | None = None) -> None:
        self.environ = os.environ if environ is None else environ
        self.before = {key: self.environ.get(key) for key in self.KEYS}
        self.claim = isolate(self.environ)

    def end(self) -> None:
        if self.claim is None:
            return
        for key, value in self.before.items():
            if value is None:
                self.environ.pop(key, None)
            else:
                self.environ[key] = value
        self.claim.release()
        self.claim = None

    def __enter__(self) -> Isolation:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.end()
