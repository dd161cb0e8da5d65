"""``Part``: what attaches to a run (the base of every part; mlaunch.engine.reactor holds them).

Apart from the reactor so that naming the base costs nothing: ``--show-args`` and ``--print``
import the pipeline, which defines parts, without importing the loop's machinery.
"""

from __future__ import annotations

from abc import ABC, abstractmethod


class Part(ABC):
    """Something attached to a run: reacts to it, and lets go of what it holds at ``close()``.

    Whoever attaches it (``Reactor.attach``) names it and says whether the run can go on
    without it.
    """

    @abstractmethod
    def close(self) -> None:
        """At the end of the run (or when it is detached): let go of threads, sockets, the
        screen."""
