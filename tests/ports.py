"""Free TCP ports on 127.0.0.1 for tests that hand one to a child (an sshd, a ROS 1 master,
the viewer), safe when several tests run at once (pytest-xdist workers, other runs).

The kernel's pick for a bind to port 0 is free at that moment, but the test closes it before
the child binds it, and in between another test could be handed the same port. Each port given
out here is also claimed with a lock file (as tests/ros_domain.py claims ROS domains), held until
this process ends, so no two tests of any run on this machine are given the same port.
"""

from __future__ import annotations

import socket

from ros_domain import try_lock

_held: list[int] = []  # the claims' descriptors: closing one would free its port for others
TRIES = 50


def free_port() -> int:
    """A port nothing listens on and no other test holds; it stays this process's."""
    for _ in range(TRIES):
        with socket.socket() as s:
            s.bind(("127.0.0.1", 0))
            port = int(s.getsockname()[1])
        fd = try_lock(f"/tmp/mlaunch-port-{port}.lock")
        if fd is None:
            continue
        _held.append(fd)
        return port
    raise RuntimeError(f"no free TCP port on 127.0.0.1 in {TRIES} tries")
