"""The readiness of ``mlaunch FILE``'s run: for systemd (``NOTIFY_SOCKET``) and ``ctl wait-ready``.

The checks are ``mlaunch test``'s (mlaunch.commands.smoke.build_expectations) for the plan the
run has: its processes, nodes, lifecycle nodes, /clock under simulated time, the file's
``Expect`` actions and the ``mlaunch_expect*`` launch arguments it declares or is given.
Watching them costs a ROS graph (rclpy), so a run attaches it only when a supervisor asks
(NOTIFY_SOCKET set: from the loop's first turn, after the first children started) or at the
first ``wait-ready`` request; a watch attached late is given the processes' history and their
last lines of output.
"""

from __future__ import annotations

import os

from mlaunch.engine.part import Part
from mlaunch.plan.records import Said

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.app.parts import Run
    from mlaunch.parts.sd_notify import Notifier
    from mlaunch.smoke.expectations import Expectation
    from mlaunch.smoke.ready import Readiness

# Lines of each process's output a late watch reads for the output checks.
SEEN_LINES = 200


def attach(run: Run) -> Part:
    """The run's readiness part: started on the loop's first turn for systemd, else on the
    first question."""
    part = LazyReadiness(run)
    run.readiness = part.state
    if not os.environ.get("NOTIFY_SOCKET"):
        return part  # (socket costs milliseconds before the first child)
    from mlaunch.parts.sd_notify import Notifier

    try:
        notifier = Notifier.from_environ(os.environ)
    except ValueError as e:
        run.supervisor.records.emit(Said("WARNING", "launch", f"{e}; systemd is not notified"))
        notifier = None
    if notifier is not None:
        run.supervisor.schedule(0.0, lambda: part.start(notifier), keeps_alive=False)
    return part


class LazyReadiness(Part):
    """Makes the Readiness part when first needed; ``state()`` answers ``wait-ready``."""

    def __init__(self, run: Run) -> None:
        self.run = run
        self.part: Readiness | None = None

    def start(self, notifier: Notifier | None = None) -> Readiness:
        if self.part is None:
            from mlaunch.smoke.ready import Readiness

            run = self.run
            expectations = run_expectations(run)
            self.part = Readiness(
                run.supervisor,
                expectations,
                notifier=notifier,
                lifecycle=run.lifecycle,
                logs=self._logs,
            )
        return self.part

    def _logs(self, label: str) -> list[str]:
        from mlaunch.parts.control import ControlError

        try:
            return self.run.control().logs(label, SEEN_LINES)
        except ControlError:
            return []

    def state(self) -> dict[str, object]:
        return self.start().state()

    def close(self) -> None:
        if self.part is not None:
            self.part.close()


def run_expectations(run: Run) -> list[Expectation]:
    """``mlaunch test``'s checks for this run's plan (no --expect options: the file's own)."""
    from mlaunch.commands.smoke import build_expectations
    from mlaunch.smoke.expectations import CONFIG_PREFIX, _CollectConfigurations, _true, parse_spec
    from mlaunch.smoke.settings import Settings

    opts, plan = run.opts, run.plan
    collector = _CollectConfigurations()
    values = {name: info.default for name, info in plan.arguments.items()}
    values.update(opts.arguments)
    for name in sorted(values):
        value = values[name]
        if name.startswith(CONFIG_PREFIX) and value:
            collector.found.append(parse_spec(str(value), f"launch argument {name}"))
    sim_time = bool(opts.use_sim_time) or _true(values.get("use_sim_time") or "false")
    return build_expectations(plan, Settings(timeout=float("inf")), collector, sim_time)
