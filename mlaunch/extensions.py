"""Optional parts that attach to a running supervisor, chosen by the command-line options.

Each entry of ATTACH is ``attach(options, supervisor) -> object | None``; an attached object
may have ``close()``, called when the run ends. Keeping the list here, explicit, means a plain
run imports none of them (STYLE.md: dispatch with explicit tables, never plugin scans).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any


def _lifecycle(options: Any, supervisor: Any) -> Any:
    """Lifecycle (managed) node driving; None unless the plan has lifecycle work."""
    from mlaunch.lifecycle import attach

    return attach(options, supervisor)


def _status_view(options: Any, supervisor: Any) -> Any:
    """``--status``: the live table pinned below the output (rich and psutil, only then)."""
    if not getattr(options, "status", False):
        return None
    from mlaunch.status import attach_status_view

    return attach_status_view(supervisor)


def _exit_summary(options: Any, supervisor: Any) -> Any:
    """The table of every process at the end (more than one process, or any failure)."""
    from mlaunch.status import ExitSummary

    return ExitSummary(supervisor, quiet=bool(getattr(options, "quiet", False)))


# Closed in this order at the end: the status view leaves the screen before the summary prints.
ATTACH: list[Callable[[Any, Any], Any]] = [_lifecycle, _status_view, _exit_summary]
