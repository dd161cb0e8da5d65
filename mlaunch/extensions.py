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


ATTACH: list[Callable[[Any, Any], Any]] = [_lifecycle]
