"""What attaches to a run of the pipeline (mlaunch.app.pipeline): the Run a part is made from,
``PartMaker`` (a part's name, how it is made, whether the run can go on without it) and
``standard_parts``, what every run gets: lifecycle driving (when the plan needs it, as resolve
noted), the LoadNode driver, the ROS clock (ROSTimers on simulated time), the control socket,
the ``--status`` view (when asked for) and the exit summary. Each part is imported only when it
is attached.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence

from mlaunch.app.options import Options
from mlaunch.engine.part import Part
from mlaunch.plan.records import HandedOff, LaunchEvent, Record, Said, SimTimeWait, Started
from mlaunch.plan.steps import Need, Plan

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.engine.output import Printer
    from mlaunch.engine.supervisor import Supervisor
    from mlaunch.parts.components import ComponentDriver
    from mlaunch.parts.control import Control
    from mlaunch.parts.control_socket import ControlSocket
    from mlaunch.parts.dashboard import Dashboard
    from mlaunch.parts.lifecycle import LifecycleManager
    from mlaunch.parts.metrics import Metrics
    from mlaunch.parts.ros_clock import SimTimeWaits


class Run:
    """What an attached part sees of the run: the command line, the plan, the supervisor and
    the printer.

    ``lifecycle`` is the LifecycleManager once lifecycle driving is attached (the smoke checks
    share its ROS graph), else None. ``readiness``: what ``ctl wait-ready`` asks, when a
    readiness part is attached. ``control`` is the run's runtime control, made on first
    use (a run that is never controlled imports nothing for it).
    """

    __slots__ = (
        "_control",
        "_metrics",
        "components",
        "launch_file",
        "lifecycle",
        "opts",
        "plan",
        "printer",
        "readiness",
        "supervisor",
    )

    def __init__(
        self,
        opts: Options,
        plan: Plan,
        supervisor: Supervisor,
        printer: Printer,
        launch_file: str = "",
    ) -> None:
        self.opts = opts
        self.launch_file = launch_file  # the launch file's path ("" when not told)
        self.plan = plan
        self.supervisor = supervisor
        self.printer = printer
        self.lifecycle: LifecycleManager | None = None
        self._control: Control | None = None
        self.components: ComponentDriver | None = None  # the LoadNode driver, once attached
        # The run's readiness as ``ctl wait-ready`` asks it (mlaunch.commands.readiness), when
        # a part that can tell is attached.
        self.readiness: Callable[[], dict[str, object]] | None = None
        self._metrics: Metrics | None = None

    def metrics(self) -> Metrics:
        """Each process's CPU, memory, threads and open files once a second (--metrics' file,
        the dashboard), made on first use as a part of its own."""
        if self._metrics is None:
            from mlaunch.parts.metrics import Metrics

            def make() -> Metrics:
                return Metrics(self.supervisor, self.control, csv_path=self.opts.metrics)

            metrics = self.supervisor.reactor.attach("the metrics", make)
            if not isinstance(metrics, Metrics):
                raise RuntimeError("the metrics failed when they were made (said above)")
            self._metrics = metrics
        return self._metrics

    def control(self) -> Control:
        """Stop, start, restart, mute, unmute a process by label, list them, read their last
        lines (mlaunch.parts.control); loop thread only."""
        if self._control is None:
            from mlaunch.parts.control import Control, ControlError

            # A part of its own, whichever part first asks for it (the socket, the keys).
            make = lambda: Control(  # noqa: E731
                self.supervisor, self.printer, lambda: self.components, lambda: self.lifecycle
            )
            control = self.supervisor.reactor.attach("runtime control", make)
            if not isinstance(control, Control):
                raise ControlError("runtime control failed when it was made (said above)")
            self._control = control
        return self._control


class PartMaker:
    """One entry of what attaches to a run: its name (errors name it), how to make it from the
    Run (None: nothing to attach), and whether the run can go on without it."""

    __slots__ = ("essential", "make", "name")

    def __init__(
        self, name: str, make: Callable[[Run], Part | None], *, essential: bool = False
    ) -> None:
        self.name = name
        self.make = make
        self.essential = essential

    def attach(self, run: Run) -> Part | None:
        """Made behind the run's wall (mlaunch.engine.reactor): a failure is said, not raised."""
        return run.supervisor.reactor.attach(
            self.name, lambda: self.make(run), essential=self.essential
        )


# --- what every run attaches ---------------------------------------------------------------------


def standard_parts(opts: Options) -> list[PartMaker]:
    """Lifecycle driving, composable node loading, the ROS clock, the control socket, the
    ``--status`` view if asked for, then the exit summary.

    Closed in this order at the end: the status view leaves the screen before the summary.
    """
    parts = [
        PartMaker("lifecycle driving", lifecycle),
        PartMaker("the LoadNode driver", components),
        PartMaker("the ROS clock", ros_clock),
        PartMaker("the control socket", control_socket),
    ]
    if opts.metrics is not None:
        parts.append(PartMaker("the metrics", metrics))
    parts.append(PartMaker("the dashboard", dashboard))
    if opts.status:
        parts.append(PartMaker("the status view", status_view))
    parts.append(PartMaker("the exit summary", exit_summary))
    return parts


def lifecycle(run: Run) -> Part:
    """Lifecycle (managed) node driving (``lifecycle_part``), kept on the Run once attached."""

    def keep(manager: LifecycleManager) -> None:
        run.lifecycle = manager

    return lifecycle_part(run.plan, run.supervisor, run.opts.arguments, keep)


def lifecycle_part(
    plan: Plan,
    supervisor: Supervisor,
    arguments: Mapping[str, str],
    keep: Callable[[LifecycleManager], None] | None = None,
) -> Part:
    """Lifecycle (managed) node driving: at once when the plan needs it, else on demand.

    Resolve records in ``plan.needs`` whatever the description says about lifecycle nodes;
    a handler written as a function can still start one nobody could see before it ran, so
    without that need a watch (a few isinstance checks per record) attaches the manager the
    moment a lifecycle node starts or a ChangeState is emitted. ``keep`` is told the manager
    when it is made. ``mlaunch FILE``, ``mlaunch test`` and ``LaunchService`` share it.
    """
    from mlaunch.plan.steps import SEQUENCE_ARGUMENT

    def make() -> LifecycleManager:
        from mlaunch.parts.lifecycle import attach

        manager = attach(arguments, supervisor)
        if keep is not None:
            keep(manager)
        return manager

    if (
        Need.LIFECYCLE in plan.needs
        or SEQUENCE_ARGUMENT in plan.arguments
        or SEQUENCE_ARGUMENT in arguments
    ):
        return make()

    def wants(record: Record) -> bool:
        if isinstance(record, Started):
            node = record.process.spec.node
            return node is not None and node.lifecycle
        if isinstance(record, HandedOff):  # a load of a lifecycle component to autostart
            return Need.LIFECYCLE in record.step.needs
        return isinstance(record, LaunchEvent) and bool(getattr(record.event, "needs", None))

    return _AttachOnDemand(supervisor, wants, make)


def components(run: Run) -> Part:
    """Composable node loading (``components_part``); the run's control reaches the driver."""

    def attached(driver: ComponentDriver) -> None:
        run.components = driver

    return components_part(run.plan, run.supervisor, attached)


def components_part(
    plan: Plan,
    supervisor: Supervisor,
    attached: Callable[[ComponentDriver], None] | None = None,
) -> Part:
    """The LoadNode driver: at once when the plan needs it, else on demand (``attached(it)``
    once it is made).

    Resolve notes in ``plan.needs`` the LoadComponents steps it made and the containers and
    LoadComposableNodes in timers and handlers not yet fired; a handler written as a function
    (or a description a LaunchService includes later) can still make one, so without that need
    a watch attaches the driver at the first LoadComponents the supervisor hands over.
    """

    def driver() -> ComponentDriver:
        from mlaunch.parts.components import ComponentDriver

        made = ComponentDriver(supervisor)
        if attached is not None:
            attached(made)
        return made

    if Need.COMPONENTS in plan.needs:
        return driver()

    def wants(record: Record) -> bool:
        return isinstance(record, HandedOff) and Need.COMPONENTS in record.step.needs

    return _AttachOnDemand(supervisor, wants, driver)


def ros_clock(run: Run) -> Part:
    """Simulated ROS time for ROSTimers (``ros_clock_part``)."""
    return ros_clock_part(run.supervisor)


def ros_clock_part(supervisor: Supervisor) -> Part:
    """The ROS clock (mlaunch.parts.ros_clock), attached at the first ROSTimer on simulated
    time the supervisor hands over (``SimTimeWait``): only whether SetUseSimTime ran when the
    timer starts tells, and a launch without one never imports it."""

    def clock() -> SimTimeWaits:
        from mlaunch.parts.ros_clock import SimTimeWaits

        return SimTimeWaits(supervisor)

    return _AttachOnDemand(supervisor, lambda event: isinstance(event, SimTimeWait), clock)


class _AttachOnDemand(Part):
    """Makes a part at the first record it ``wants`` (a step handed over that needs it).

    Until then it only looks at each record's class; the record that triggered it is handed to
    the new part, which sees every later record itself.
    """

    def __init__(
        self,
        supervisor: Supervisor,
        wants: Callable[[Record], bool],
        make: Callable[[], ComponentDriver | SimTimeWaits | LifecycleManager],
    ) -> None:
        self.supervisor = supervisor
        self.wants = wants
        self.make = make
        self.driver: ComponentDriver | SimTimeWaits | LifecycleManager | None = None
        supervisor.records.subscribe(self._on_record)

    def _on_record(self, record: Record) -> None:
        if not self.wants(record):
            return
        self.supervisor.records.unsubscribe(self._on_record)
        driver = self.driver = self.make()
        driver.on_record(record)

    def close(self) -> None:
        self.supervisor.records.unsubscribe(self._on_record)
        if self.driver is not None:
            self.driver.close()


def control_socket(run: Run) -> Part | None:
    """``mlaunch ctl``'s socket in the run's log folder (mlaunch.parts.control_socket)."""
    log_dir = run.printer.log_dir
    return _ControlSocketPart(run, log_dir) if log_dir else None


class _ControlSocketPart(Part):
    """Opens the control socket on the loop's first turn, and removes it at close.

    After the first children have started: ``socket`` and ``json`` cost milliseconds, which
    opening it at attach time would spend before the first child.
    """

    def __init__(self, run: Run, log_dir: str) -> None:
        self.run = run
        self.log_dir = log_dir
        self.server: ControlSocket | None = None
        run.supervisor.schedule(0.0, self._open, keeps_alive=False)

    def _open(self) -> None:
        from mlaunch.parts.control_socket import ControlSocket

        supervisor = self.run.supervisor
        server = ControlSocket(
            supervisor, self.run.control, self.log_dir, readiness=lambda: self.run.readiness
        )
        if server.open():
            self.server = server
        else:
            text = f"{server.error}; mlaunch ctl cannot reach this run"
            supervisor.records.emit(Said("WARNING", "launch", text))

    def close(self) -> None:
        if self.server is not None:
            self.server.close()


def metrics(run: Run) -> None:
    """--metrics FILE.csv: the run's metrics, a part of their own (``Run.metrics``)."""
    run.metrics()


# The viewer stand-in's module: its page shows the launch panel (mlaunch.parts.dashboard).
VIEWER_MODULE = "mlaunch.standins.viewer"


def dashboard(run: Run) -> Part | None:
    """The launch panel: with --dashboard at once, else when the viewer stand-in starts."""
    if run.opts.dashboard_port is not None:
        return dashboard_part(run)
    return _ViewerWatch(run)


def dashboard_part(run: Run) -> Dashboard:
    from mlaunch.parts.dashboard import Dashboard

    def composable() -> list[dict[str, object]]:
        driver = run.components
        return [] if driver is None else driver.listed()

    panel: list[Dashboard] = []

    def readiness() -> object:
        # Watching the checks costs mlaunch a ROS graph (rclpy, a dozen threads): begun when a
        # page first looks, not because the viewer stand-in runs (a late watch gets the history).
        if run.readiness is None or not (panel and panel[0].hub.looked):
            return None
        return run.readiness()

    metrics = run.metrics()
    metrics.readers["readiness"] = readiness  # mlaunch test's checks, as ctl wait-ready has them
    metrics.readers["lifecycle"] = lambda: run.lifecycle.listed() if run.lifecycle else []
    dashboard = Dashboard(
        run.supervisor,
        run.control,
        metrics,
        port=run.opts.dashboard_port,
        composable=composable,
        evidence=lambda processes, rings: live_evidence(run, processes, rings),
    )
    panel.append(dashboard)
    return dashboard


def live_evidence(run: Run, processes: Sequence[Any], rings: Mapping[str, Sequence[str]]) -> bytes:
    """The launch panel's evidence bundle: ``mlaunch test``'s evidence writer run on the
    launch so far (no verdict, no gdb) into a temporary folder, packed as a .tar.gz."""
    import tempfile

    from mlaunch.resolve.plan_json import plan_json
    from mlaunch.smoke import artifacts
    from mlaunch.smoke.watch import RING_LINES

    path = run.launch_file or run.opts.target
    name = f"mlaunch-evidence-{run.supervisor.run_id}"
    with tempfile.TemporaryDirectory(prefix="mlaunch-evidence-") as folder:
        artifacts.write(
            folder,
            verdict=None,
            plan_text=plan_json(run.plan, path, run.opts.arguments),
            processes=processes,
            rings={label: list(lines)[-RING_LINES:] for label, lines in rings.items()},
            log_dir=run.printer.log_dir or "",
            backtraces=False,
        )
        data, _left = artifacts.pack(folder, name)
    return data


class _ViewerWatch(Part):
    """Attaches the launch panel when a viewer stand-in starts (its page shows the panel)."""

    def __init__(self, run: Run) -> None:
        self.run = run
        self.panel: Dashboard | None = None
        run.supervisor.records.subscribe(self._on_record)

    def _on_record(self, record: Record) -> None:
        if not isinstance(record, Started) or VIEWER_MODULE not in record.process.spec.argv:
            return
        self.run.supervisor.records.unsubscribe(self._on_record)
        self.panel = dashboard_part(self.run)

    def close(self) -> None:
        self.run.supervisor.records.unsubscribe(self._on_record)
        if self.panel is not None:
            self.panel.close()


def status_view(run: Run) -> Part | None:
    """``--status``: the live table pinned below the output (rich and psutil, only then)."""
    from mlaunch.parts.status import attach_status_view

    return attach_status_view(run.supervisor, run.printer, run.control)


class _ExitSummary(Part):
    """Prints mlaunch.parts.summary's exit summary at close, importing it only then.

    Importing it costs start-up time that attaching before the run would spend before the first
    child starts.
    """

    def __init__(self, supervisor: Supervisor, *, quiet: bool) -> None:
        self.supervisor = supervisor
        self.quiet = quiet

    def close(self) -> None:
        from mlaunch.parts.summary import ExitSummary

        supervisor = self.supervisor
        ExitSummary(supervisor.process_states, supervisor.records.emit, quiet=self.quiet).close()


def exit_summary(run: Run) -> Part:
    """The table of every process at the end (more than one process, or any failure)."""
    return _ExitSummary(run.supervisor, quiet=run.opts.quiet)
