"""Optional parts that attach to a running supervisor, chosen by the command-line options.

Each entry of ATTACH is ``attach(options, supervisor) -> object | None``; an attached object
may have ``close()``, called when the run ends. Keeping the list here, explicit, means a plain
run imports none of them (STYLE.md: dispatch with explicit tables, never plugin scans).
"""

from __future__ import annotations

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable
    from typing import Any


def _lifecycle(options: Any, supervisor: Any) -> Any:
    """Lifecycle (managed) node driving; None unless the plan has lifecycle work."""
    if not _may_have_lifecycle_work(options, supervisor.plan):
        return None
    from mlaunch.ros.lifecycle import attach

    return attach(options, supervisor)


def _may_have_lifecycle_work(options: Any, plan: Any) -> bool:
    """A cheap look that can rule lifecycle out without importing mlaunch.ros.lifecycle (~5 ms).

    False only when nothing in the plan can involve a managed node; lifecycle.attach then
    makes the exact decision.
    """
    import sys

    if "mlaunch.ros.lifecycle" in sys.modules:  # a LifecycleSequence or Expect was built
        return True
    sequence = "mlaunch_lifecycle_sequence"
    if sequence in plan.arguments or sequence in getattr(options, "arguments", {}):
        return True
    deferred = False
    for step in plan.steps:
        spec = getattr(step, "spec", None)
        if spec is not None and spec.node is not None and spec.node.lifecycle:
            return True
        if getattr(step, "kind", "") == "state_transition":
            return True
        if type(getattr(step, "event", None)).__name__ == "ChangeState":
            return True
        deferred = deferred or getattr(step, "body", None) is not None
        deferred = deferred or (spec is not None and spec.on_exit is not None)
    # Deferred parts resolve later; a lifecycle node can only be among them if the ROS
    # actions were loaded.
    return deferred and "mlaunch.launch_ros.actions" in sys.modules


def _components(options: Any, supervisor: Any) -> Any:
    """Composable node loading; None unless the plan loads components (resolve made a step)."""
    import sys

    if "mlaunch.launch_ros.composition" not in sys.modules:
        return None  # no container or LoadComposableNodes was built: nothing to load
    from mlaunch.ros.components import attach

    return attach(options, supervisor)


def _status_view(options: Any, supervisor: Any) -> Any:
    """``--status``: the live table pinned below the output (rich and psutil, only then)."""
    if not getattr(options, "status", False):
        return None
    from mlaunch.run.status import attach_status_view

    return attach_status_view(supervisor)


class _ExitSummary:
    """Prints mlaunch.run.status's exit summary at close, importing it only then.

    mlaunch.run.status (with typing) costs ~1.5 ms, which attaching before the run would spend
    before the first child starts.
    """

    def __init__(self, supervisor: Any, *, quiet: bool) -> None:
        self.supervisor = supervisor
        self.quiet = quiet

    def close(self) -> None:
        from mlaunch.run.status import ExitSummary

        ExitSummary(self.supervisor, quiet=self.quiet).close()


def _exit_summary(options: Any, supervisor: Any) -> Any:
    """The table of every process at the end (more than one process, or any failure)."""
    return _ExitSummary(supervisor, quiet=bool(getattr(options, "quiet", False)))


# Closed in this order at the end: the status view leaves the screen before the summary prints.
ATTACH: list[Callable[[Any, Any], Any]] = [_lifecycle, _components, _status_view, _exit_summary]
