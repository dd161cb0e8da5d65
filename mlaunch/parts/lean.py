"""What keeps the launcher's own rclpy side small: its DDS participant and its malloc arenas.

Measured on Autoware's planning_simulator (55 processes, 53 composable nodes in 27 load steps),
the launcher's peak RSS, best of alternating runs:

- ``lean_participant``: the launcher's participant with Fast DDS's UDPv4 transport only, not
  UDPv4 + shared memory (the builtin pair): about 4 MB, and three threads, fewer. A LoadNode
  request and its answer are a few hundred bytes; over shared memory the launcher maps a port
  segment of every participant it talks to. Discovery is UDP either way.
- ``limit_arenas``: glibc gives each thread that allocates under contention an arena of its own
  (up to 8 per core); the launcher's DDS and load threads then keep pages in a dozen of them.
  Two arenas: about 1.5 MB.

Both apply to this process only: ``mallopt`` is undone by the exec of a child, and the transport
setting is in this process's environment only while its participant is made, on the thread that
resolves and spawns (children get the plan's environment, never os.environ's at that moment),
and only when that is the main thread (mlaunch's own run).
A user's own Fast DDS configuration (a profile file, FASTDDS_BUILTIN_TRANSPORTS, another RMW) is
left as it is.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator, Mapping, MutableMapping
from contextlib import contextmanager

TRANSPORTS = "FASTDDS_BUILTIN_TRANSPORTS"
# Any of these set: the user configures the middleware; the launcher's participant follows it.
USER_SETTINGS = (
    TRANSPORTS,
    "FASTRTPS_DEFAULT_PROFILES_FILE",
    "FASTDDS_DEFAULT_PROFILES_FILE",
    "RMW_FASTRTPS_USE_QOS_FROM_XML",
    "ROS_DISCOVERY_SERVER",
)
FAST_DDS = ("", "rmw_fastrtps_cpp", "rmw_fastrtps_dynamic_cpp")

# glibc's mallopt parameter for the most arenas (malloc.h: M_ARENA_MAX).
M_ARENA_MAX = -8
ARENAS = 2


def lean_transports(environ: Mapping[str, str]) -> bool:
    """True when the launcher's participant may be made with UDPv4 only: Fast DDS is the RMW
    and the user has not configured its transports or profiles."""
    if environ.get("RMW_IMPLEMENTATION", "") not in FAST_DDS:
        return False
    return not any(environ.get(name) for name in USER_SETTINGS)


@contextmanager
def lean_participant(environ: MutableMapping[str, str] | None = None) -> Iterator[None]:
    """While inside, a participant this process makes uses UDPv4 only (see the module).

    ``environ``: the process's environment (os.environ); a test passes a dict. Call it only on
    the thread that resolves and spawns: it sets os.environ for that while. Off the main thread
    (a LaunchService run by launch_testing beside the tests' own thread, which may spawn with
    os.environ) it does nothing.
    """
    import threading

    env = os.environ if environ is None else environ
    if threading.current_thread() is not threading.main_thread() or not lean_transports(env):
        yield
        return
    env[TRANSPORTS] = "UDPv4"
    try:
        yield
    finally:
        env.pop(TRANSPORTS, None)


def limit_arenas(mallopt: Callable[[int, int], int] | None = None) -> bool:
    """At most ``ARENAS`` malloc arenas in this process from now on (glibc; else nothing)."""
    if mallopt is None:
        import ctypes

        try:
            mallopt = ctypes.CDLL(None).mallopt  # the process's own libc
        except (OSError, AttributeError):  # not glibc (musl has no mallopt)
            return False
    return bool(mallopt(M_ARENA_MAX, ARENAS))
