"""``Part``: what attaches to a run (the base of every part; mlaunch.engine.reactor holds them).

Apart from the reactor so that naming the base costs nothing: ``--show-args`` and ``--print``
import the pipeline, which defines parts, without importing the loop's machinery.

``AttachedRun`` is what every part may use of the run it is attached to (the Supervisor is
one): its record stream, its timers, the loop's selector and clock. A part that needs more names
it in a protocol of its own that extends this one, so a part can be read, and tested, without
the whole Supervisor.
"""

from __future__ import annotations

from abc import ABC, abstractmethod

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    import selectors
    from collections.abc import Callable
    from typing import Protocol

    from mlaunch.engine.timers import Timer
    from mlaunch.plan.records import RecordStream

    class AttachedRun(Protocol):
        """What every part may use of its run: subscribe to the records and emit its own,
        schedule timers, register files in the loop's selector (what a part registers or
        schedules is its own: mlaunch.engine.reactor), read the loop's clock."""

        @property
        def records(self) -> RecordStream: ...

        @property
        def selector(self) -> selectors.BaseSelector: ...

        @property
        def clock(self) -> Callable[[], float]: ...

        def schedule(
            self,
            delay: float,
            callback: Callable[[], object],
            *,
            keeps_alive: bool = True,
            cancel_on_shutdown: bool = True,
        ) -> Timer: ...

    class EndingRun(Protocol):
        """What a part that may end the run uses: whether it is ending, its exit status, the
        start of its shutdown."""

        @property
        def shutting_down(self) -> bool: ...

        def exit_status(self, code: int) -> None: ...

        def begin_shutdown(self, reason: str, *, due_to_signal: int | None = None) -> None: ...


class Part(ABC):
    """Something attached to a run: reacts to it, and lets go of what it holds at ``close()``.

    Whoever attaches it (``Reactor.attach``) names it and says whether the run can go on
    without it.
    """

    @abstractmethod
    def close(self) -> None:
        """At the end of the run (or when it is detached): let go of threads, sockets, the
        screen."""
