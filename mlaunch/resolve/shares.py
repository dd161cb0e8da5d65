"""``mlaunch FILE --machine NAME``: one machine's share of a launch, checked after resolve.

The whole launch is resolved on every machine (the same arguments give the same conditions,
labels and parameters everywhere); the resolver turns each process of another share into an
``Elsewhere`` step (mlaunch.resolve.resolver). What is checked here: the share names a machine
the launch declares (or ``local``: the processes given no machine), and which event handlers
wait for a process this run does not start: such a handler fires only in the run that starts
its target, which carries out only its own share of what the handler does.
"""

from __future__ import annotations

from mlaunch.plan.machine import LOCAL_SHARE
from mlaunch.plan.steps import AddHandler, Elsewhere, Plan
from mlaunch.plan.text import rel

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

# Handlers that wait for one process's events (the others are for the run or for any process).
PROCESS_EVENTS = {
    "process_start": "starts",
    "process_exit": "exits",
    "process_io": "writes output",
    "state_transition": "changes lifecycle state",
}


def check_share(plan: Plan, run_state: dict[str, Any], share: str) -> None:
    """Refuse a share the launch does not have; warn of handlers waiting for another share."""
    from mlaunch.plan.errors import UsageError

    declared = sorted(run_state.get("machines") or {})
    if share == LOCAL_SHARE and LOCAL_SHARE in declared:
        raise UsageError(
            f"--machine {LOCAL_SHARE}: the launch declares a machine named {LOCAL_SHARE!r}, and"
            f" '{LOCAL_SHARE}' also names the processes given no machine; rename that machine"
        )
    if share != LOCAL_SHARE and share not in declared:
        known = ", ".join(declared) if declared else "none"
        raise UsageError(
            f"--machine {share}: the launch declares no machine {share!r} (declared: {known});"
            f" valid: a declared machine, or '{LOCAL_SHARE}' for the processes given no machine"
        )
    plan.warnings.extend(handler_warnings(plan, share))


def handler_warnings(plan: Plan, share: str) -> list[str]:
    """One warning per handler that waits for a process of another share."""
    elsewhere = [s.spec for s in plan.steps if isinstance(s, Elsewhere) and s.spec is not None]
    if not elsewhere:
        return []
    out = []
    for step in plan.steps:
        if not isinstance(step, AddHandler) or step.matcher is None:
            continue
        verb = PROCESS_EVENTS.get(step.kind)
        if verb is None:
            continue
        for spec in elsewhere:
            try:
                matched = bool(step.matcher(spec))
            except Exception:  # a user's matcher: it decides in the run that has the process
                matched = False
            if matched:
                out.append(
                    f"{rel(step.origin) or '?'}: the handler for when {spec.label} {verb} never"
                    f" fires in this run (--machine {share}): {spec.label} is"
                    f" {_share_of(spec)}'s share; it fires in the run of --machine"
                    f" {_share_of(spec)}, which starts only its own share of what the"
                    " handler starts"
                )
                break
    return out


def _share_of(spec: Any) -> str:
    return LOCAL_SHARE if spec.machine is None else str(spec.machine.name)
