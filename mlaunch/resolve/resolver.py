"""Resolve: a launch description + arguments + environment -> a Plan. Nothing is spawned here.

The resolver visits the description depth first, evaluating conditions and substitutions
against a LaunchContext. Deferred parts (timers, handlers, on_exit) are captured with their
context and resolved later by ``resolve_deferred``, with the same code.
"""

from __future__ import annotations

import itertools
import os

from mlaunch.frontends.limits import DEPTH_LIMIT, IncludeChain, allow_deep_trees, too_deep
from mlaunch.launch.launch_context import LaunchContext
from mlaunch.launch.planning import number
from mlaunch.launch.substitution import perform_substitutions
from mlaunch.plan.errors import (
    LaunchFileError,
    MlaunchError,
    PackageNotFoundError,
    SubstitutionFailure,
    is_own_module,
)
from mlaunch.plan.origin import unset_variable_hint, user_location
from mlaunch.plan.steps import (
    SHARE,
    ArgumentInfo,
    Deferred,
    Elsewhere,
    Handoff,
    Need,
    Plan,
    ProcessSpec,
    Spawn,
    Step,
    step_needs,
)
from mlaunch.plan.value import Value

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable, Iterable, Mapping
    from typing import Any, TypeVar

    R = TypeVar("R")

    from mlaunch.launch.launch_description_entity import LaunchDescriptionEntity
    from mlaunch.ros.search import PackageSearch, searching

# --check notes at most this many errors of one file (a loop over a broken include stops).
COLLECT_LIMIT = 100


class LabelCounter:
    """ROS 2's global ``name-N`` counter, shared by everything resolved in one run, with the
    run's own planning state (``LaunchContext.run_state``: the declared machines ...)."""

    def __init__(self) -> None:
        self._next = itertools.count(1)
        self.run_state: dict[str, Any] = {}

    def next(self, base: str) -> str:
        return f"{base}-{next(self._next)}"


class ResolveOptions(Value):
    """What the caller decides about resolution, besides the description and its arguments.

    ``packages`` is where ROS packages are looked for (a mlaunch.ros.search.PackageSearch,
    None for the default search); ``temp_dir`` is where params files are written.
    """

    _fields = (
        "standins",
        "packages",
        "temp_dir",
        "capture",
        "scoped_parameters",
        "scoped_file_locals",
        "dry_run",
        "collect",
        "log_levels",
        "machine",
    )
    __slots__ = _fields

    def __init__(
        self,
        standins: bool = True,
        packages: PackageSearch | None = None,
        temp_dir: str | None = None,
        capture: bool = False,
        scoped_parameters: bool = False,
        dry_run: bool = False,
        scoped_file_locals: bool = False,
        collect: list[MlaunchError] | None = None,
        log_levels: tuple[str, ...] = (),
        machine: str | None = None,
    ) -> None:
        self.standins = standins
        self.packages = packages
        self.temp_dir = temp_dir
        # Timers and handlers take the values where they were written (mlaunch.resolve.binding).
        self.capture = capture
        # SetParameter(s)FromFile stay inside scoped groups (mlaunch.launch_ros.actions).
        self.scoped_parameters = scoped_parameters
        # An include's ThisLaunchFileDir ... stays in the include (mlaunch.launch.file_locals).
        self.scoped_file_locals = scoped_file_locals
        # --print: a program that is not built or installed is a warning and the plan is shown
        # (a dry run on a laptop); a run refuses it before anything starts.
        self.dry_run = dry_run
        # --check: an action that fails is noted here and the visit goes on with the next one,
        # so one check names every error a run would stop at (None: the first error raises).
        self.collect = collect
        # --log-level: each item given to every ROS node's command line (--log-level ITEM).
        self.log_levels = log_levels
        # --machine NAME: start only that machine's share (``local``: the processes given no
        # machine); the other processes are Elsewhere steps (mlaunch.plan.machine.placed).
        self.machine = machine


class Resolver:
    """Visits entities against one context, appending steps to one plan."""

    def __init__(
        self,
        context: LaunchContext,
        plan: Plan,
        *,
        labels: LabelCounter,
        options: ResolveOptions,
    ) -> None:
        self.context = context
        self.plan = plan
        self.labels = labels
        self.options = options
        self.includes = IncludeChain()  # include cycles are errors, not a RecursionError
        # The descriptions includes returned, not visited yet -> (file or None, include's
        # origin, the file's locals, whether they are scoped to it, the includer's locals)
        self.included: dict[int, tuple[str | None, str, dict[str, str], bool, dict[str, Any]]] = {}
        self.visiting = ""  # the origin of the action being visited (what warnings name)
        self.depth = 0
        allow_deep_trees()
        context.planner = self  # the seam: actions plan through their context (plan.planner)
        context.run_state = labels.run_state

    # --- visiting -----------------------------------------------------------------------------

    def visit(self, entity: object) -> None:
        if self.depth >= DEPTH_LIMIT:
            origin = getattr(entity, "origin", None)
            raise too_deep(origin, "launch actions (groups, includes)", includes=self.includes)
        self.depth += 1
        outer = self.visiting
        self.visiting = getattr(entity, "origin", None) or outer
        try:
            included = self.included.pop(id(entity), None)
            if included is None:
                self._visit(entity)
            else:
                self._visit_included(entity, *included)
        finally:
            self.depth -= 1
            self.visiting = outer

    def _visit_included(
        self,
        description: object,
        path: str | None,
        origin: str,
        file_locals: dict[str, str],
        scoped: bool,
        before: dict[str, Any],
    ) -> None:
        """An included description: in the chain of includes when it is a file's, with the
        file's locals, and after it the includer's or launch's (mlaunch.launch.file_locals)."""
        from mlaunch.launch.file_locals import enter, leave

        enter(self.context, file_locals)
        try:
            if path is None:
                self._visit(description)
            else:
                with self.includes.enter(path, origin, self.context):
                    self._visit(description)
        finally:
            leave(self.context, before, scoped)

    def _visit(self, entity: object) -> None:
        visit = getattr(entity, "visit", None)
        if visit is None:
            raise LaunchFileError(
                f"{type(entity).__name__} ({entity!r:.60}) is not a launch action"
                " (expected actions such as Node, ExecuteProcess, DeclareLaunchArgument)"
            )
        try:
            more = visit(self.context)
        except MlaunchError as e:
            origin = getattr(entity, "origin", None)
            if e.where is None and origin:
                e.where = origin
            if e.what is None and not isinstance(e, LaunchFileError):
                e.what = _short(entity)
            self._name_declaration(e)
            if not self._collected(e):
                raise
            return
        except Exception as e:
            if is_own_module(type(entity).__module__):
                raise  # mlaunch's own action failing is mlaunch's bug
            failure = self._foreign_failure(entity, e)
            if not self._collected(failure):
                raise failure from e
            return
        if more:
            self.visit_all(more)

    def _collected(self, error: MlaunchError) -> bool:
        """Whether ``error`` was noted for --check (the visit goes on) rather than raised."""
        found = self.options.collect
        if found is None or len(found) >= COLLECT_LIMIT:
            return False
        if not any(str(f) == str(error) for f in found):  # an include visited twice, a loop
            found.append(error)
        return True

    def _foreign_failure(self, entity: object, error: Exception) -> MlaunchError:
        """An action class of a launch file or a package (an exposed tag) that raised: where it
        raised, and where the action was written."""
        origin = getattr(entity, "origin", None)
        where = user_location(error.__traceback__, self.context.current_launch_file_path)
        written = f" (the action written at {origin})" if origin and where else ""
        return MlaunchError(
            f"{type(error).__name__} in {type(entity).__name__}: {error}{written}",
            where=where or origin,
        )

    def _name_declaration(self, error: MlaunchError) -> None:
        """Add where the launch argument a bad value came from is declared (once)."""
        info = self.plan.arguments.get(error.argument or "")
        if info is None or not info.origin:
            return
        error.message += f" (launch argument {error.argument!r}, declared at {info.origin})"
        error.args = (error.message,)
        error.argument = None

    def visit_all(self, entities: Iterable[object]) -> None:
        for entity in entities:
            self.visit(entity)

    def call_user(self, function: Callable[..., R], *args: object, **kwargs: object) -> R:
        """Call launch-file code (OpaqueFunction), locating any exception in the user's file."""
        try:
            return function(*args, **kwargs)
        except MlaunchError:
            raise
        except SystemExit as e:  # sys.exit() in launch-file code must not end mlaunch silently
            from mlaunch.frontends.python import exit_error

            path = self.context.current_launch_file_path or ""
            raise exit_error(e, path, "in a function of the launch file") from e
        except Exception as e:
            where = user_location(e.__traceback__, self.context.current_launch_file_path)
            hint = unset_variable_hint(e)
            raise MlaunchError(f"{type(e).__name__}: {e}{hint}", where=where) from e

    # --- what actions use ---------------------------------------------------------------------

    def add(self, step: Step) -> None:
        if SHARE in self.labels.run_state and isinstance(step, Handoff):
            step = _share_handoff(self.labels.run_state, step)
        self.plan.steps.append(step)
        needs = step_needs(step)
        if needs:
            self.plan.needs.update(needs)

    def spawn(self, spec: ProcessSpec) -> None:
        if spec.standin is not None:
            from mlaunch import standins

            standins.equip(spec)
        if SHARE in self.labels.run_state:  # --machine NAME: one machine's share of the launch
            self.add(_share_spawn(self.labels.run_state, spec))
            return
        self.add(Spawn(origin=spec.origin, spec=spec))

    def emit(self, event: object, step: Step | None) -> None:
        if step is not None:
            self.add(step)

    def warn(self, message: str) -> None:
        self.plan.warnings.append(message)

    def declare_argument(self, info: ArgumentInfo) -> ArgumentInfo:
        return self.plan.arguments.setdefault(info.name, info)

    def include(
        self,
        description: object,
        path: str | None,
        origin: str,
        file_locals: dict[str, str],
        scoped: bool,
    ) -> None:
        # the includer's locals, before the include points them at the file
        before = self.context.get_locals_as_dict_of_scope()
        self.included[id(description)] = (path, origin, file_locals, scoped, before)

    def new_label(self, base: str) -> str:
        return self.labels.next(base)

    def defer(
        self,
        entities: Iterable[object],
        origin: str = "",
        callback: Callable[..., object] | None = None,
    ) -> Deferred:
        from mlaunch.plan.pragmas import file_captures

        entities = list(entities)
        # Resolved only when they fire: what they may need must be known before the run.
        _note_needs(entities, self.plan.needs)
        snapshot = self.context.snapshot()
        if self.options.capture or (origin and file_captures(origin)):
            return Deferred(entities, snapshot, origin, callback)
        return Deferred(entities, self.context, origin, callback, captured=snapshot)

    def float_value(self, value: object, what: str, origin: str) -> float:
        return number(self.context, value, what, origin)

    def load_source(self, source: object, origin: str) -> object:
        """The LaunchDescription an include names (built directly, or loaded from its file)."""
        from mlaunch.launch.launch_description_source import LaunchDescriptionSource

        if not isinstance(source, LaunchDescriptionSource):
            raise LaunchFileError(
                f"{source!r:.60} is not a launch description source", where=origin
            )
        if source.launch_description is not None:
            return source.launch_description
        from mlaunch import readers

        path = source.get_launch_file_location(self.context)
        if path is None or not os.path.exists(path):
            raise LaunchFileError(f"included launch file {path!r} does not exist", where=origin)
        return readers.load(path, source.format_hint)

    def locate_program(
        self, argv: list[str], *, shell: bool, origin: str
    ) -> tuple[list[str], str | None]:
        """argv with a stand-in in place of a program that is not installed.

        Returns the argv and the name of what a stand-in replaces (None when the real program
        runs). A program that is neither installed nor covered by a stand-in is an error here,
        before anything starts, naming the program.
        """
        if shell:
            return argv, None
        program = argv[0]
        env = self.context.environment
        if os.sep in program:
            if os.access(program, os.X_OK) and not os.path.isdir(program):
                return argv, None
        else:
            from mlaunch.launch.actions.execute_process import which

            if which(program, env) is not None:
                return argv, None
        from mlaunch import standins

        if self.options.standins:
            replaced = standins.standin_for(argv)
            if replaced is not None:
                return replaced, os.path.basename(program)
        hint = standins.hint_for(argv) if not self.options.standins else ""
        if os.sep in program:
            problem = "does not exist" if not os.path.exists(program) else "is not executable"
            error = PackageNotFoundError(f"program {program!r} {problem}{hint}", where=origin)
        else:
            error = PackageNotFoundError(
                f"program {program!r} not found on the PATH{hint}", where=origin
            )
        if not self.options.dry_run:
            raise error
        if not any(f"shown as {program!r}," in w for w in self.plan.warnings):  # a Node's, said
            self.warn(f"{error}; a run refuses to start without it")
        return argv, None


# What the share of a run (--machine NAME) notes of each node it meets: here, or elsewhere.
SHARE_NODES = "share_nodes"


def _share_spawn(run_state: dict[str, Any], spec: ProcessSpec) -> Step:
    """A Spawn when ``spec`` is of this run's share, else an Elsewhere step (not started here).

    A process of the share starts as that machine's agent starts it over ssh: through the
    machine's env-loader when it has one (a program on that machine that sets the environment
    and runs its arguments), ``shell=True`` commands under ``/bin/sh -c`` behind it.
    """
    from mlaunch.plan.machine import machine_name, runs_elsewhere

    elsewhere = runs_elsewhere(run_state.get(SHARE), spec.machine)
    node = spec.node.fully_qualified_name if spec.node is not None else None
    if node:
        run_state.setdefault(SHARE_NODES, {})[node] = not elsewhere
    if elsewhere:
        return Elsewhere(spec.origin, machine_name(spec.machine), spec=spec)
    loader = spec.machine.env_loader if spec.machine is not None else None
    if loader:
        if spec.shell:
            spec.argv = (loader, "/bin/sh", "-c", " ".join(spec.argv))
            spec.shell = False
        else:
            spec.argv = (loader, *spec.argv)
        spec.launch_prefix = (loader, *spec.launch_prefix)
    return Spawn(origin=spec.origin, spec=spec)


def _share_handoff(run_state: dict[str, Any], step: Handoff) -> Step:
    """A load into a container (a Handoff with a ``target`` node) is the container's share's:
    an Elsewhere step in the other shares. A container the launch does not start (loaded into
    by name) is the local share's, so that one run loads it, not every machine's."""
    from mlaunch.plan.machine import LOCAL_SHARE

    target = getattr(step, "target", None)
    if not isinstance(target, str):
        return step
    here = run_state.get(SHARE_NODES, {}).get(target)
    if here is None:
        here = run_state.get(SHARE) == LOCAL_SHARE
    return step if here else Elsewhere(step.origin, "", step=step)


def _note_needs(entities: Iterable[Any], needs: set[Need]) -> None:
    """Add what ``entities`` (a timer's or handler's, not yet resolved) and theirs may need.

    An entity says so with a ``needs`` attribute (LifecycleNode, LifecycleSequence), or its
    event or event handler does (ChangeState, OnStateTransition). A handler written as a
    function is opaque until it runs; the pipeline watches for what it starts instead.
    """
    from mlaunch.launch.walk import walk

    for visit in walk(entities):
        entity = visit.entity
        handler = getattr(entity, "event_handler", None)
        for owner in (entity, getattr(entity, "event", None), handler):
            found = getattr(owner, "needs", None)
            if found:
                needs.update(found)


def _short(entity: Any) -> str:
    """The action an error names; cut at 200 characters (a command line of substitutions
    built 200 deep describes itself in kilobytes, and an error is one line)."""
    describe = getattr(entity, "describe_short", None)
    text = describe() if describe else type(entity).__name__
    return text if len(text) <= 200 else text[:197] + "..."


# --- entry points ------------------------------------------------------------------------------


def resolve(
    description: LaunchDescriptionEntity,
    *,
    path: str | None,
    arguments: Mapping[str, str],
    environ: Mapping[str, str],
    log_dir: str = "",
    options: ResolveOptions | None = None,
    labels: LabelCounter | None = None,
    noninteractive: bool = False,
) -> Plan:
    """Resolve a whole launch description, as the top-level include of the command line."""
    options = options or ResolveOptions()
    plan = Plan(temp_dir=options.temp_dir)
    context = LaunchContext(
        environment=environ,
        argv=tuple(f"{k}:={v}" for k, v in arguments.items()),
        noninteractive=noninteractive,
        log_dir=log_dir,
        warn=plan.warnings.append,
    )
    context.launch_configurations.update(arguments)
    labels = labels or LabelCounter()
    if options.machine is not None:
        labels.run_state[SHARE] = options.machine
    resolver = Resolver(context, plan, labels=labels, options=options)
    with _package_search(options, context):
        if path is None:
            resolver.visit(description)
        else:
            with context.file_locals(path):
                resolver.visit(description)
    plan.warnings.extend(undeclared_argument_warnings(arguments, plan.arguments))
    return plan


def resolve_deferred(
    deferred: Deferred,
    *,
    labels: LabelCounter,
    options: ResolveOptions,
    event: Any = None,
    shutting_down: bool = False,
) -> Plan:
    """Resolve a timer's or handler's entities now, in the context captured when registered.

    ``shutting_down``: the run is shutting down, which the contexts of the run say from now on
    (``is_shutdown``, as launch's: a fixture's exit during shutdown is no failure).
    """
    plan = Plan(temp_dir=options.temp_dir)
    live = deferred.context
    if not isinstance(live, LaunchContext):
        raise TypeError(f"a deferred step's context is {type(live).__name__}, not a LaunchContext")
    if shutting_down:
        live._set_is_shutdown(True)
    if deferred.captured is None:
        context = live.snapshot()
    else:
        # launch's rule: the live state, which the body's own actions change for later ones.
        context = live
        captured = deferred.captured
        assert isinstance(captured, LaunchContext)
        from mlaunch.resolve.binding import differences, warn_once

        diffs = differences(captured, context, deferred.entities, deferred.callback)
        message = warn_once(captured, deferred.origin, diffs, deferred.describe())
        if message:
            plan.warnings.append(message)
    # the live context's locals (and planner) are the event's only now
    values = context.get_locals_as_dict_of_scope()
    if isinstance(deferred.captured, LaunchContext):
        # The locals where the body was written (ThisLaunchFileDir, $(dirname) ...), as launch's
        # TimerAction restores the locals it captured: the file visited last is not the body's.
        values.update(deferred.captured.get_locals_as_dict_of_scope())
    if event is not None:
        values["event"] = event
    with context.lend(values, plan.warnings.append):
        resolver = Resolver(context, plan, labels=labels, options=options)
        with _package_search(options, context):
            entities = deferred.entities
            if deferred.callback is not None:
                from mlaunch.launch.event_handler import returned_entities

                entities = returned_entities(resolver.call_user(deferred.callback, event, context))
            resolver.visit_all(entities)
    return plan


class _NoSearch:
    def __enter__(self) -> None:
        return None

    def __exit__(self, *exc_info: object) -> None:
        return None


def _package_search(options: ResolveOptions, context: LaunchContext) -> _NoSearch | searching:
    """The run's package search: in the context for Node and the ROS substitutions, and active
    for ament_index_python calls of the launch-file code that resolving runs (included files
    being loaded, OpaqueFunctions)."""
    if options.packages is None:
        return _NoSearch()
    from mlaunch.ros.search import CONTEXT_KEY, searching

    context.extend_globals({CONTEXT_KEY: options.packages})
    return searching(options.packages)


# Launch configurations that launch itself reads (ExecuteProcess's prefix, set by
# --launch-prefix/--launch-prefix-filter or as name:=value): given undeclared on purpose.
BUILTIN_CONFIGURATIONS = frozenset({"launch-prefix", "launch-prefix-filter"})


def undeclared_argument_warnings(
    given: Mapping[str, str], declared: Mapping[str, ArgumentInfo]
) -> list[str]:
    undeclared = [
        name for name in given if name not in declared and name not in BUILTIN_CONFIGURATIONS
    ]
    if not undeclared:  # the common case imports nothing more (start-up budget)
        return []
    from mlaunch.frontends.suggest import Suggester

    suggest = Suggester(declared)
    return [
        f"argument {name!r} is not declared by the launch file{suggest.hint(name)}"
        for name in undeclared
    ]


# --- --show-args: a static walk ------------------------------------------------------------------


def collect_arguments(
    description: LaunchDescriptionEntity,
    *,
    path: str | None,
    arguments: Mapping[str, str],
    environ: Mapping[str, str],
) -> list[ArgumentInfo]:
    """Every DeclareLaunchArgument, following includes whose path can be resolved statically.

    Conditional declarations (under a condition, in a timer or handler) are marked; nothing is
    spawned and no command substitution beyond what an include path needs is run.
    """
    from mlaunch.launch.actions.declare_launch_argument import DeclareLaunchArgument
    from mlaunch.launch.walk import walk

    found: dict[str, ArgumentInfo] = {}
    context = LaunchContext(environment=environ)
    context.launch_configurations.update(arguments)
    seen: set[str] = set()

    def declare(roots: list[object], conditional: bool, passed: Mapping[str, str]) -> None:
        """Declare what ``roots`` declare; ``passed``: the names an including file passes."""

        def include_here(entity: object, conditional: bool) -> list[object]:
            return include(entity, conditional, passed)

        for visit in walk(roots, include=include_here):
            entity = visit.entity
            if not isinstance(entity, DeclareLaunchArgument):
                continue
            info = found.setdefault(
                entity.name, entity.argument_info(conditional or visit.conditional)
            )
            info.passed_by = info.passed_by or passed.get(info.name, "")
            if info.name not in context.launch_configurations and entity.default_value:
                try:
                    value = perform_substitutions(context, entity.default_value)
                except MlaunchError:
                    continue
                context.launch_configurations[info.name] = value
                if info.default != value:
                    info.resolved = value

    def include(entity: object, conditional: bool, passed: Mapping[str, str]) -> list[object]:
        """Declare what a statically found include declares, with its file's locals; the walk
        goes on after it (so the order of declarations is the file's)."""
        passed = {**passed, **_passed_names(entity, context)}
        source = entity.launch_description_source  # type: ignore[attr-defined]
        if source.launch_description is not None:
            declare([source.launch_description], conditional, passed)
            return []
        try:
            location = source.get_launch_file_location(context)
        except (MlaunchError, SubstitutionFailure):
            return []
        if location in seen or not os.path.exists(location):
            return []
        seen.add(location)
        from mlaunch import readers

        with context.file_locals(location):
            declare([readers.load(location, source.format_hint)], conditional, passed)
        return []

    if path is None:
        declare([description], False, {})
    else:
        with context.file_locals(path):
            declare([description], False, {})
    return list(found.values())


def _passed_names(include: Any, context: LaunchContext) -> dict[str, str]:
    """The argument names an IncludeLaunchDescription passes -> its origin (file:line)."""
    names = {}
    for name, _value in getattr(include, "launch_arguments", None) or ():
        try:
            text = name if isinstance(name, str) else perform_substitutions(context, name)
        except MlaunchError:
            continue
        names[text] = getattr(include, "origin", "") or "the including file"
    return names
