"""The run's open-file limit: enough descriptors for every process, never a crash half-way.

Each child costs the supervisor about PER_PROCESS descriptors (its stdin, stdout and stderr
pipes, its log file), so 500 processes do not fit the common soft limit of 1024. Before the
first spawn, a plan that needs more than the soft limit raises it (up to the hard limit), and
children get the user's own soft limit back (``child_setup``: systemd's rule, since a program
that select()s or closes every descriptor up to the limit must not see a raised one); a plan
whose pipes alone cannot fit the hard limit is refused before anything starts. A spawn that
still runs out (processes a handler starts later) raises the limit and tries once more
(``make_room``). A run that needs no more than the soft limit changes nothing: its children
start without ``child_setup`` (a preexec function doubles the cost of a spawn).
"""

from __future__ import annotations

import resource
from collections.abc import Callable

from mlaunch.plan.errors import UsageError

# Descriptors the supervisor holds per running child: three pipes and a log file.
PER_PROCESS = 4
# Descriptors that certainly stay open per child (its pipes; a log file opens on first output).
PIPES = 3
# What the run holds besides its children: the guard, the log folder, the control socket and
# its clients (mlaunch.parts.control_socket keeps 64 free on its own), the ROS bridge.
RESERVE = 192
# Below this, nothing the run holds is at risk (mlaunch's own files at start: ~30).
BASE = 32


class Limit:
    """The run's RLIMIT_NOFILE: what the user gave (``original``) and whether it was raised."""

    def __init__(self) -> None:
        self.original, self.hard = resource.getrlimit(resource.RLIMIT_NOFILE)
        self.raised = False

    def prepare(self, processes: int) -> None:
        """Before the first spawn of a plan of ``processes``: raise the soft limit if they need
        more, or refuse (UsageError) if their pipes alone exceed the hard limit."""
        need = processes * PER_PROCESS + RESERVE
        if need <= self.soft():
            return
        least = processes * PIPES + BASE
        if self.hard != resource.RLIM_INFINITY and least > self.hard:
            raise UsageError(
                f"{processes} processes need at least {least} open files ({PIPES} pipes each;"
                f" about {need} with their log files), more than the hard limit of {self.hard}"
                " (ulimit -Hn); raise it (ulimit -Hn, systemd's LimitNOFILE=) or start fewer"
                " processes; nothing was started"
            )
        self._raise_to(max(need, 2 * self.soft()))

    def make_room(self) -> bool:
        """A spawn ran out of descriptors (EMFILE): raise the soft limit; False if it cannot."""
        return self._raise_to(2 * self.soft())

    def soft(self) -> int:
        soft, _ = resource.getrlimit(resource.RLIMIT_NOFILE)
        return soft if soft != resource.RLIM_INFINITY else 1 << 30

    def _raise_to(self, wanted: int) -> bool:
        target = wanted if self.hard == resource.RLIM_INFINITY else min(wanted, self.hard)
        if target <= self.soft():
            return False
        try:
            resource.setrlimit(resource.RLIMIT_NOFILE, (target, self.hard))
        except (ValueError, OSError):
            return False
        self.raised = True
        return True

    def child_setup(self) -> Callable[[], None] | None:
        """What a child runs before exec to get the user's soft limit back (None: not raised)."""
        if not self.raised:
            return None
        limits = (self.original, self.hard)

        def restore() -> None:
            resource.setrlimit(resource.RLIMIT_NOFILE, limits)

        return restore


# One per mlaunch process: the limit is the process's.
LIMIT: Limit | None = None


def limit() -> Limit:
    global LIMIT
    if LIMIT is None:
        LIMIT = Limit()
    return LIMIT
