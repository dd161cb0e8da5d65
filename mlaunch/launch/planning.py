"""The planner of a context that no run made: an action visited on its own collects its steps.

Resolve gives every context it visits its own planner (``mlaunch.resolve.resolver.Resolver``).
A ``LaunchContext()`` made by a script or by the unit test of an extension has none until it is
first asked; then it gets this one, which runs the same action code, keeps the steps in
``plan`` and the warnings in ``plan.warnings``, and starts nothing.
"""

from __future__ import annotations

import itertools

from mlaunch.plan.errors import LaunchFileError, MlaunchError
from mlaunch.plan.steps import Deferred, Plan, Spawn, step_needs

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable, Iterable
    from typing import Any, TypeVar

    from mlaunch.launch.launch_context import LaunchContext
    from mlaunch.plan.planner import Planner
    from mlaunch.plan.steps import ArgumentInfo, ProcessSpec, Step

    R = TypeVar("R")


class StandaloneOptions:
    """Planning options of a standalone context: real programs only, nothing scoped."""

    __slots__ = ()
    standins = False
    dry_run = False
    log_levels: tuple[str, ...] = ()
    temp_dir: str | None = None
    capture = False
    scoped_parameters = False
    scoped_file_locals = False


class StandalonePlanner:
    """Collects the steps of actions visited with one context (see the module docstring)."""

    def __init__(self, context: LaunchContext) -> None:
        self.context = context
        self.plan = Plan()
        self.options = StandaloneOptions()
        self._labels = itertools.count(1)
        self._scoped: dict[int, tuple[dict[str, str], dict[str, Any]]] = {}
        self.visiting = ""  # the origin of the action being visited (what warnings name)

    def add(self, step: Step) -> None:
        self.plan.steps.append(step)
        self.plan.needs.update(step_needs(step))

    def spawn(self, spec: ProcessSpec) -> None:
        self.add(Spawn(origin=spec.origin, spec=spec))

    def emit(self, event: object, step: Step | None) -> None:
        """Plan the step, and hold the event in the context's queue as upstream's bare context
        does: nothing runs the plan, so a caller can see what the actions emitted."""
        if step is not None:
            self.add(step)
        self.context._event_queue.put_nowait(event)

    def warn(self, message: str) -> None:
        self.plan.warnings.append(message)
        warn = getattr(self.context, "warn", None)
        if warn is not None:
            warn(message)
        else:  # an object that only looks like a context: say it as upstream does, by logging
            import logging

            logging.getLogger("launch").warning(message)

    def new_label(self, base: str) -> str:
        return f"{base}-{next(self._labels)}"

    def declare_argument(self, info: ArgumentInfo) -> ArgumentInfo:
        return self.plan.arguments.setdefault(info.name, info)

    def defer(
        self,
        entities: Iterable[object],
        origin: str = "",
        callback: Callable[..., object] | None = None,
    ) -> Deferred:
        return Deferred(list(entities), self.context.snapshot(), origin, callback)

    def visit(self, entity: object) -> None:
        visit = getattr(entity, "visit", None)
        if visit is None:
            raise LaunchFileError(
                f"{type(entity).__name__} ({entity!r:.60}) is not a launch action"
            )
        scoped = self._scoped.pop(id(entity), None)
        if scoped is not None:
            self.context._locals.update(scoped[0])
        outer = self.visiting
        self.visiting = getattr(entity, "origin", None) or outer
        try:
            more = visit(self.context)
            if more:
                self.visit_all(more)
        finally:
            self.visiting = outer
            if scoped is not None:
                self.context._locals = scoped[1]

    def visit_all(self, entities: Iterable[object]) -> None:
        for entity in entities:
            self.visit(entity)

    def call_user(self, function: Callable[..., R], *args: object, **kwargs: object) -> R:
        return function(*args, **kwargs)

    def include(
        self,
        description: object,
        path: str | None,
        origin: str,
        file_locals: dict[str, str],
        scoped: bool,
    ) -> None:
        """Launch's rule needs nothing here (the include already set the file's locals, and they
        stay); a scoped include's file gets its own, and the includer's after it."""
        if scoped:
            self._scoped[id(description)] = (file_locals, dict(self.context._locals))

    def load_source(self, source: object, origin: str) -> object:
        built = getattr(source, "launch_description", None)
        if built is not None:
            return built
        locate = getattr(source, "get_launch_file_location", None)
        path = locate(self.context) if locate is not None else None
        load = getattr(source, "load_file", None)
        if path is not None and load is not None:
            return load(path)
        raise MlaunchError(
            f"{source!r} names no launch file and holds no description", where=origin
        )

    def locate_program(
        self, argv: list[str], *, shell: bool, origin: str
    ) -> tuple[list[str], str | None]:
        return argv, None

    def float_value(self, value: object, what: str, origin: str) -> float:
        return number(self.context, value, what, origin)


def planner_of(context: object) -> Planner:
    """The planner of ``context``, or a standalone one for an object that only offers what
    upstream's code reads (a mock context of a test: launch configurations, locals ...).

    Such an object cannot keep a planner, so each call plans apart: what it plans is not kept.
    """
    planner: Planner | None = getattr(context, "planner", None)
    if planner is None:
        planner = StandalonePlanner(context)  # type: ignore[arg-type]
    return planner


def number(context: LaunchContext, value: object, what: str, origin: str) -> float:
    """A finite number from a number or substitutions, or a located error naming ``what``."""
    from mlaunch.launch.substitution import perform

    text = value if isinstance(value, (int, float)) else perform(context, value)
    try:
        result = float(text)
    except (TypeError, ValueError):
        raise MlaunchError(f"{what} is {text!r}, expected a number", where=origin)
    if result != result or result in (float("inf"), float("-inf")):
        raise MlaunchError(f"{what} is {text!r}, expected a finite number", where=origin)
    return result
