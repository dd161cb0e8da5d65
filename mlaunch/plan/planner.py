"""The seam between a launch action and what executes it: the ``Planner`` a context carries.

Launch actions follow upstream's contract: ``entity.visit(context)`` returns the entities to
visit next (or None), and ``Action.visit`` evaluates the condition, then calls
``execute(context)``. Whatever an action makes happen at run time (a process, a timer, an event
handler, an event, a shutdown) it hands to ``context.planner`` as a step of the Plan; the engine
carries the steps out in order. Resolve (``mlaunch.resolve.resolver.Resolver``) is the planner of
a run; a bare ``LaunchContext()`` gets a standalone one (``mlaunch.launch.planning``) that
collects the steps, so an action can be visited on its own, as unit tests of extensions do.

This layer knows no launch classes: entities and contexts are ``object`` here, and each side of
the seam types them itself. Only type checkers import this module (typing costs start-up time).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import Protocol, TypeVar

from mlaunch.plan.steps import ArgumentInfo, Deferred, ProcessSpec, Step

R = TypeVar("R")


class PlanningOptions(Protocol):
    """What the caller decided about planning that actions read."""

    @property
    def standins(self) -> bool: ...  # stand-ins may replace programs that are not installed

    @property
    def temp_dir(self) -> str | None: ...  # where params files are written

    @property
    def capture(self) -> bool: ...  # timers and handlers take the values where written

    @property
    def scoped_parameters(self) -> bool: ...  # SetParameter stays in its scoped group

    @property
    def scoped_file_locals(self) -> bool: ...  # an include's file locals stay in the include

    @property
    def dry_run(self) -> bool: ...  # --print: a program not built is a warning, not an error

    @property
    def log_levels(self) -> tuple[str, ...]: ...  # --log-level: given to every ROS node


class Planner(Protocol):
    """How an action's execution becomes steps of a Plan (see the module docstring)."""

    @property
    def options(self) -> PlanningOptions: ...

    @property
    def visiting(self) -> str: ...  # the origin of the action being visited (what warnings name)

    def add(self, step: Step) -> None:
        """Append a step to the plan being built."""

    def spawn(self, spec: ProcessSpec) -> None:
        """Append the start of a process."""

    def emit(self, event: object, step: Step | None) -> None:
        """An event given to the context: ``step`` emits it in the plan (None: nothing to add,
        an included description is visited instead); a standalone planner also holds it."""

    def warn(self, message: str) -> None:
        """A warning of planning, said once before the run."""

    def new_label(self, base: str) -> str:
        """launch's global ``name-N`` label for a process."""

    def declare_argument(self, info: ArgumentInfo) -> ArgumentInfo:
        """Note a launch argument; the first declaration of a name wins and is returned."""

    def defer(
        self,
        entities: Iterable[object],
        origin: str = "",
        callback: Callable[..., object] | None = None,
    ) -> Deferred:
        """Entities (or a function returning them) to visit when a timer or handler fires."""

    def visit(self, entity: object) -> None:
        """Visit one entity now, then whatever its visit returns."""

    def visit_all(self, entities: Iterable[object]) -> None:
        """Visit entities in order."""

    def call_user(self, function: Callable[..., R], *args: object, **kwargs: object) -> R:
        """Call launch-file code, locating its exceptions in the user's file."""

    def include(
        self,
        description: object,
        path: str | None,
        origin: str,
        file_locals: dict[str, str],
        scoped: bool,
    ) -> None:
        """``description`` (what an include returns to visit next) is the file at ``path``
        (None: a description given as such): visited as an include (a cycle is an error, not
        recursion), with ``file_locals`` (ThisLaunchFile ...) inside. ``scoped``: the includer's
        locals are back after it (ros2/launch PR #862); otherwise they stay the file's, as in
        Jazzy (the include already set them), and only mlaunch's record of the includer's own
        locals comes back (what the warning of ThisLaunchFileDir compares with)."""

    def load_source(self, source: object, origin: str) -> object:
        """The LaunchDescription an include's source names, built or loaded from its file."""

    def locate_program(
        self, argv: list[str], *, shell: bool, origin: str
    ) -> tuple[list[str], str | None]:
        """argv with a stand-in for a program that is not installed, and what it replaces."""

    def float_value(self, value: object, what: str, origin: str) -> float:
        """A finite number from a number or substitutions, or a located error."""
