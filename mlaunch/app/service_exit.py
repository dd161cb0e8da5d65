"""What ends a LaunchService's threaded run when the Python process exits while it still runs.

``run_async`` and ``run_in_thread`` run the launch on a daemon thread, so the interpreter does
not wait for it at exit (a thread joined at exit would wait forever for a launch nobody shuts
down: a test that dropped its task kept pytest alive). Instead an ``atexit`` hook, registered
when the first threaded run starts, shuts every run still going down through the stop ladder
and waits for it, bounded: daemon threads still run while atexit hooks do.
"""

from __future__ import annotations

import atexit
import threading
import weakref

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Protocol

    class ThreadedRun(Protocol):
        def stop_at_exit(self) -> None: ...


# The services whose run is on a thread of its own; weak, so a finished one is not kept.
_running: weakref.WeakSet[ThreadedRun] = weakref.WeakSet()
_lock = threading.Lock()
_hooked = False


def watch(service: ThreadedRun) -> None:
    """Stop ``service``'s run at interpreter exit if it is still going then."""
    global _hooked
    with _lock:
        if not _hooked:
            atexit.register(stop_all)
            _hooked = True
        _running.add(service)


def forget(service: ThreadedRun) -> None:
    """``service``'s run has ended."""
    with _lock:
        _running.discard(service)


def stop_all() -> None:
    """Stop every threaded run still going (the atexit hook; each waits for its own run)."""
    with _lock:
        services = list(_running)
    for service in services:
        service.stop_at_exit()
