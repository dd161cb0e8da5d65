"""A private ROS_DOMAIN_ID for one test or benchmark run: the one lock both take.

A lock file per id (``/tmp/mlaunch-ros-domain-<id>.lock``) held with flock while the domain is
in use, so overlapping pytest runs, CI and a benchmark never share a DDS domain and never see
each other's nodes. benchmarks/run.py and scripts/smoke_repeat.py import this module too.
"""

from __future__ import annotations

import fcntl
import os
import random
from collections.abc import Callable, Iterator
from contextlib import contextmanager

FIRST, LAST = 101, 199  # inside ROS 2's valid range, away from the default 0


def try_lock(path: str) -> int | None:
    """A descriptor of ``path`` holding its exclusive lock, or None when another process holds
    it; the lock lasts until the descriptor is closed (tests/ports.py claims ports so too)."""
    fd = os.open(path, os.O_CREAT | os.O_RDWR, 0o666)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        os.close(fd)
        return None
    return fd


def claim(skip: Callable[[int], bool] | None = None) -> tuple[int, int]:
    """(domain, fd): a domain no other run holds; it stays held until ``fd`` is closed.

    ``skip(domain)`` can refuse a free lock too (a leftover process still using the domain).
    """
    ids = list(range(FIRST, LAST + 1))
    random.shuffle(ids)
    for domain in ids:
        fd = try_lock(f"/tmp/mlaunch-ros-domain-{domain}.lock")
        if fd is None:
            continue
        if skip is not None and skip(domain):
            os.close(fd)
            continue
        return domain, fd
    raise RuntimeError(f"no free ROS_DOMAIN_ID in {FIRST}..{LAST}")


@contextmanager
def private_domain() -> Iterator[int]:
    """``with private_domain() as domain_id:`` a domain held for the block."""
    domain, fd = claim()
    try:
        yield domain
    finally:
        os.close(fd)
