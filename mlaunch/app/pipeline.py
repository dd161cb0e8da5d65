"""One run of a launch file: load -> resolve -> supervise, with an explicit list of what attaches.

``mlaunch FILE``, ``mlaunch test FILE`` and ``mlaunch export`` go through here; none reaches
into another. What attaches to a run is a list of functions the caller passes to ``launch`` or
``supervise``: a ``PartMaker`` names a part and makes it from the Run (after the supervisor
exists, before it starts); the part (mlaunch.engine.reactor.Part) subscribes to the supervisor's
record stream, and is closed, in list order, when the run ends. Each part is behind a wall: if it
raises, the run says so, detaches it and goes on (mlaunch.engine.reactor). The Run, the
PartMaker and what every run attaches (``standard_parts``) are mlaunch.app.parts'. Nothing here
imports rclpy, rich or psutil unless a part that needs them is attached.
"""

from __future__ import annotations

import os
from collections.abc import Sequence

from mlaunch.app.options import Options, own_log_level
from mlaunch.app.parts import PartMaker, Run
from mlaunch.plan.records import Said
from mlaunch.plan.steps import SHARE, Plan

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.app.plan_cache import PlanCache
    from mlaunch.app.quick import Prestart
    from mlaunch.engine.lifeline import Lifeline
    from mlaunch.launch.launch_description import LaunchDescription
    from mlaunch.launch.launch_description_entity import LaunchDescriptionEntity
    from mlaunch.parts.remote import Spawner
    from mlaunch.resolve.resolver import LabelCounter, ResolveOptions
    from mlaunch.ros.search import PackageSearch


# --- load and resolve ---------------------------------------------------------------------------


def find_launch_file(opts: Options) -> str:
    """The launch file path: a file, or PKG FILE looked up in the package's share folder."""
    from mlaunch.plan.errors import LaunchFileError

    if opts.second is None:
        if not os.path.exists(opts.target):
            raise LaunchFileError(f"launch file {opts.target!r} does not exist{_near(opts.target)}")
        return os.path.abspath(opts.target)
    from mlaunch.ros import packages

    return packages.find_launch_file(opts.target, opts.second)


def _near(path: str) -> str:
    """A did-you-mean among the files of the folder ``path`` names."""
    from mlaunch.plan.errors import closest

    folder, name = os.path.split(path)
    try:
        entries = sorted(os.listdir(folder or "."))
    except OSError:
        return ""
    close = closest(name, entries)
    return f" (did you mean {os.path.join(folder, close)!r}?)" if close else ""


def package_search(opts: Options, launch_file: str | None) -> PackageSearch:
    """Where this run looks for ROS packages: --package-path, the launch file, the environment."""
    from mlaunch.ros.search import PackageSearch

    return PackageSearch(opts.package_path, launch_file, os.environ, standins=opts.standins)


def find_target(opts: Options) -> tuple[str, PackageSearch]:
    """The launch file the command line names (a path, or PKG FILE) and the run's package search,
    made once: the search that found the file, unless naming the file changes it."""
    from mlaunch.ros.search import searching

    # `mlaunch PKG FILE` looks the package up with the search settings, before there is a file.
    given = os.path.abspath(opts.target) if opts.second is None else None
    search = package_search(opts, given if given and os.path.exists(given) else None)
    with searching(search):
        path = find_launch_file(opts)
    if search.launch_file != path:
        search = package_search(opts, path)
    return path, search


def load_target(opts: Options, temp_dir: str | None = None) -> tuple[str, LaunchDescription]:
    """The launch file the command line names (a path, or PKG FILE) and its description."""
    path, search = find_target(opts)
    return path, load_file(opts, path, search, temp_dir)


def load_file(
    opts: Options, path: str, search: PackageSearch, temp_dir: str | None = None
) -> LaunchDescription:
    """The description of the launch file at ``path``, loaded with the run's package search.

    A roslaunch file runs natively on ROS 1 (``mlaunch.parts.ros1_native``, its files in
    ``temp_dir``) with --ros1, or in a shell set up for ROS 1 unless --ros2 says otherwise.
    """
    from mlaunch import readers
    from mlaunch.frontends.python import set_launch_argv
    from mlaunch.ros.search import searching

    set_launch_argv(opts.target, opts.second, opts.launch_argv)
    # Launch-file code run while loading (get_package_share_directory) sees the same search.
    with searching(search):
        if temp_dir is not None and native_ros1(opts, path):
            from mlaunch.parts import ros1_native

            if opts.machine is not None:
                from mlaunch.plan.errors import UsageError

                raise UsageError(
                    f"--machine {opts.machine}: a native ROS 1 run (its master and parameter"
                    " server) is not split by machine; run the file on ROS 2 (--ros2), or whole"
                )

            native: LaunchDescription = ros1_native.description(
                path, opts.arguments, os.environ, temp_dir
            )
            return native
        return readers.load(path)


def native_ros1(opts: Options, path: str) -> bool:
    """Whether a run of ``path`` is a native ROS 1 one (--ros1 / --ros2, else the shell)."""
    from mlaunch import readers

    roslaunch_file = readers.frontend_for(path) == readers.FRONTENDS[".launch"]
    if opts.ros == 1 and not roslaunch_file:
        from mlaunch.plan.errors import UsageError

        raise UsageError(f"--ros1 runs roslaunch files (*.launch), not {path!r}")
    if not roslaunch_file or opts.ros == 2:
        return False
    from mlaunch.parts import ros1_native  # (a roslaunch file: nothing on a ROS 2 run's path)

    return opts.ros == 1 or ros1_native.wants_native(path, os.environ)


def resolve_for_run(
    opts: Options,
    path: str,
    description: LaunchDescriptionEntity,
    *,
    temp_dir: str,
    log_dir: str,
    search: PackageSearch | None = None,
) -> tuple[Plan, ResolveOptions, LabelCounter]:
    """(plan, resolve options, label counter) for a run of ``description`` as opts say;
    ``search``: the run's package search, when the caller made it (``find_target``)."""
    from mlaunch.resolve.resolver import LabelCounter, ResolveOptions, resolve

    options = ResolveOptions(
        standins=opts.standins,
        packages=search or package_search(opts, path),
        temp_dir=temp_dir,
        capture=opts.capture,
        scoped_parameters=opts.scoped_parameters,
        scoped_file_locals=opts.scoped_file_locals,
        dry_run=opts.print_plan,
        log_levels=tuple(opts.log_levels),
        machine=opts.machine,
    )
    if opts.use_sim_time is not None:
        from mlaunch.launch_ros.actions.set_parameter import with_use_sim_time

        description = with_use_sim_time(description, opts.use_sim_time)
    labels = LabelCounter()
    plan = resolve(
        description,
        path=path,
        arguments=opts.arguments,
        environ=dict(os.environ),
        log_dir=log_dir,
        options=options,
        labels=labels,
        noninteractive=opts.noninteractive,
    )
    if opts.machine is not None:
        from mlaunch.resolve.shares import check_share

        check_share(plan, labels.run_state, opts.machine)
    return plan, options, labels


# --- the whole pipeline --------------------------------------------------------------------------


def launch(opts: Options, attach: Sequence[PartMaker], quick: Prestart | None = None) -> int:
    """``mlaunch FILE``: load, resolve, then list the arguments, print the plan, or run it.

    ``quick``: the quick start of this command line (mlaunch.app.quick): its lifeline and the
    children it started, which the run adopts; else its entry is written once the plan is known.
    Given (a ``Prestart`` at least: ``mlaunch FILE``), the plan's first processes start as soon
    as the plan is known, before the supervisor is made.
    """
    from mlaunch.engine.lifeline import Lifeline

    # From here on a launch file's code and substitutions may start processes: signals, the
    # guard and the run's marker cover them (a slow Command is when SIGTERM tends to arrive).
    with quick.life if quick is not None and quick.life is not None else Lifeline() as life:
        if opts.show_args:
            return show_arguments(opts, life)
        cache = plan_cache(opts)
        if cache is not None:
            entry = cache.lookup()
            if entry is not None:
                log_dir = run_log_dir(opts)
                from mlaunch.app.plan_cache import places

                cached = cache.take(entry, places(life.temp_dir, log_dir, life.run_id, os.environ))
                if cached is not None:
                    from mlaunch.frontends.python import set_launch_argv

                    set_launch_argv(opts.target, opts.second, opts.launch_argv)
                    plan, options, labels = cached.plan, cached.options, cached.labels
                    note_quick(quick, plan, life, log_dir, cache)
                    return run_plan(
                        opts, plan, options, labels, log_dir, life, attach, cached.path, quick
                    )
            return resolve_recorded(opts, cache, life, attach, quick)
        path, search = find_target(opts)
        description = load_file(opts, path, search, temp_dir=life.temp_dir)
        streams_back(path)
        log_dir = run_log_dir(opts)
        plan, options, labels = resolve_for_run(
            opts, path, description, temp_dir=life.temp_dir, log_dir=log_dir, search=search
        )
        streams_back(path)
        return run_plan(opts, plan, options, labels, log_dir, life, attach, path, quick)


def plan_cache(opts: Options) -> PlanCache | None:
    """The run's entry in the plan cache, or None (--no-cache, MLAUNCH_NO_CACHE)."""
    from mlaunch.app.options import cache_wanted

    if not cache_wanted(opts, os.environ):
        return None  # the cache's code is not even imported
    from mlaunch.app.plan_cache import PlanCache
    from mlaunch.engine.lifeline import say

    return PlanCache.for_run(opts, os.environ, say)


def note_quick(
    quick: Prestart | None, plan: Plan, life: Lifeline, log_dir: str, cache: PlanCache
) -> None:
    """Write the quick entry of a plan the cache holds, unless this run was quick-started."""
    from mlaunch.app.quick import QuickStart

    if not isinstance(quick, QuickStart) or quick.found or cache.inputs_data is None:
        return
    if not quick.note(plan, life.run_id, (life.temp_dir, log_dir), cache.inputs_data):
        cache.debug(f"no quick start: {quick.why_not}")


def resolve_recorded(
    opts: Options,
    cache: PlanCache,
    life: Lifeline,
    attach: Sequence[PartMaker],
    quick: Prestart | None = None,
) -> int:
    """Load and resolve as ``launch`` does, noting every input, and store the plan when the
    recording saw everything it depends on (``--debug`` and ``--print`` say when not)."""
    from mlaunch.plan import inputs

    path = ""
    # The move into the run's cgroup (a thread of its own while the file loads) writes
    # cgroup.procs: finished first, or the recording would take that for the launch's own write
    # and refuse to store the plan (on a cold run only; a cached one does not record).
    life.settle()
    with cache.record(life.temp_dir) as recording:
        path, search = find_target(opts)
        if native_ros1(opts, path):
            recording.refuse("a native ROS 1 run (its master and parameter server are the run's)")
        description = load_file(opts, path, search, temp_dir=life.temp_dir)
        streams_back(path)
        with inputs.paused():
            log_dir = run_log_dir(opts)
        recording.own = (
            (*recording.own, os.path.abspath(log_dir) + os.sep) if log_dir else recording.own
        )
        plan, options, labels = resolve_for_run(
            opts, path, description, temp_dir=life.temp_dir, log_dir=log_dir, search=search
        )
    streams_back(path)
    from mlaunch.app.plan_cache import places

    run_places = places(life.temp_dir, log_dir, life.run_id, os.environ)
    stored = cache.store(recording, path, plan, options, labels, run_places)
    if not stored and opts.print_plan and not opts.debug:
        from mlaunch.engine.lifeline import say

        say(f"mlaunch: plan cache: not stored: {cache.why_not}")
    if stored:
        note_quick(quick, plan, life, log_dir, cache)
    return run_plan(opts, plan, options, labels, log_dir, life, attach, path, quick)


def run_log_dir(opts: Options) -> str:
    """The run's log folder (made now), or "" for --print."""
    if opts.print_plan:
        return ""
    from mlaunch.engine.logfiles import make_run_log_dir

    return make_run_log_dir(os.environ)


def run_plan(
    opts: Options,
    plan: Plan,
    options: ResolveOptions,
    labels: LabelCounter,
    log_dir: str,
    life: Lifeline,
    attach: Sequence[PartMaker],
    path: str,
    quick: Prestart | None = None,
) -> int:
    """Print the plan (--print), or run it (adopting what ``quick`` started)."""
    if opts.print_plan:
        from mlaunch.engine.lifeline import write_stdout

        write_stdout(describe(opts, plan, path))
        return 0
    return supervise(opts, plan, options, labels, log_dir, life, attach, path=path, quick=quick)


def show_arguments(opts: Options, life: Lifeline) -> int:
    """``--show-args``: the launch arguments of the file and of what it includes."""
    from mlaunch.engine.lifeline import write_stdout
    from mlaunch.resolve.describe import format_arguments
    from mlaunch.resolve.resolver import collect_arguments
    from mlaunch.ros.search import searching

    path, search = find_target(opts)
    description = load_file(opts, path, search, temp_dir=life.temp_dir)
    streams_back(path)
    with searching(search):
        infos = collect_arguments(
            description, path=path, arguments=opts.arguments, environ=os.environ
        )
    if opts.format == "json":
        from mlaunch.resolve.plan_json import arguments_json

        write_stdout(arguments_json(infos, path, opts.arguments))
    else:
        write_stdout(format_arguments(infos))
    return 0


def streams_back(path: str) -> None:
    """Reopen the standard streams the launch file's code closed (it runs in this interpreter)."""
    from mlaunch.engine.lifeline import ensure_std_streams, say

    for name in ensure_std_streams():
        say(f"mlaunch: warning: {path} closed sys.{name}; mlaunch opened it again for itself")


def describe(opts: Options, plan: Plan, path: str) -> str:
    """``--print``: the plan as text (resolve.describe) or JSON (resolve.plan_json)."""
    if opts.format == "json":
        from mlaunch.resolve.plan_json import plan_json

        return plan_json(plan, path, opts.arguments)
    from mlaunch.resolve.describe import describe_plan

    return describe_plan(plan, path)


def supervise(
    opts: Options,
    plan: Plan,
    options: ResolveOptions,
    labels: LabelCounter,
    log_dir: str,
    life: Lifeline,
    attach: Sequence[PartMaker],
    *,
    path: str = "",
    quick: Prestart | None = None,
) -> int:
    """Run ``plan`` with the lifeline's guard, the printer and ``attach``'s parts; ``path`` is
    the launch file (the parts' ``Run.launch_file``); ``quick``'s children are adopted, and
    when it started none, the plan's first processes start before the supervisor is made
    (``Prestart.start_first``) unless the run raised its descriptor limit for them."""
    from mlaunch.plan.errors import UsageError

    if opts.log_max_bytes is not None and opts.log_max_bytes < 0:
        raise UsageError(
            f"--log-max-bytes is {opts.log_max_bytes}; valid: 0 (never rotate) or more"
        )
    from mlaunch.engine import fdlimit

    # 500 processes need more descriptors than the common soft limit: raised, or refused now.
    limit = fdlimit.limit()
    limit.prepare(len(plan.processes()))
    if quick is not None and not quick.children and not limit.raised:
        quick.start_first(plan, life)
    from mlaunch.engine.logfiles import DEFAULT_ROTATE_BYTES, DEFAULT_ROTATE_KEEP
    from mlaunch.engine.output import Printer, stdout_is_color_terminal
    from mlaunch.engine.process import Process
    from mlaunch.engine.supervisor import Supervisor

    guard, run_id = life.guard, life.run_id
    color = stdout_is_color_terminal(os.environ) if opts.color is None else opts.color
    rotate = DEFAULT_ROTATE_BYTES if opts.log_max_bytes is None else opts.log_max_bytes
    printer = Printer(
        color=color,
        log_dir=log_dir,
        quiet=opts.quiet,
        level=own_log_level(opts.log_levels),
        rotate_bytes=rotate,
        rotate_keep=DEFAULT_ROTATE_KEEP if opts.log_keep is None else opts.log_keep,
    )
    spawner = _remote_spawner(labels, run_id)
    supervisor = Supervisor(
        plan,
        printer,
        options=options,
        labels=labels,
        guard=guard,
        run_id=run_id,
        spawner=Process if spawner is None else spawner,
        prestarted=quick if quick is not None and quick.children else None,
    )
    supervisor.records.emit(Said("INFO", "launch", f"All log files can be found below {log_dir}"))
    run = Run(opts, plan, supervisor, printer, launch_file=path)
    try:
        life.settle()  # mlaunch is in the run's cgroup before it starts anything itself
        if spawner is not None:
            spawner.connect(plan.processes())
        for maker in attach:
            maker.attach(run)
        life.block()  # until the supervisor's own handlers are in
        try:
            code = supervisor.run()
        finally:
            life.hand_over()
    finally:
        supervisor.reactor.close_all()
        if spawner is not None:
            spawner.close()
        printer.close()
        # Everything the run started has ended (run() kills what is left even when it fails).
        if guard is not None:
            guard.close()
    return code


def _remote_spawner(labels: LabelCounter, run_id: str) -> Spawner | None:
    """The remote-process spawner when the launch declared other machines, else None."""
    if not labels.run_state.get("machines"):
        return None  # no Machine in the launch: mlaunch.machines is never imported
    if SHARE in labels.run_state:
        return None  # --machine: its share runs here, the others' are not started
    from mlaunch.plan.machine import remote_machines

    if not remote_machines(labels.run_state):
        return None
    from mlaunch.engine.proctable import MARKER
    from mlaunch.parts.remote import Spawner

    return Spawner(os.environ, {MARKER: run_id})
