"""``launch.launch_description``: ``LaunchDescription``, an ordered list of entities (what
``generate_launch_description()`` returns), and the launch arguments it declares.
"""

from __future__ import annotations

from mlaunch.launch.launch_description_entity import LaunchDescriptionEntity
from mlaunch.plan.origin import caller_origin

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Iterable
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext


class LaunchDescription(LaunchDescriptionEntity):
    """An ordered list of entities; what generate_launch_description() returns."""

    def __init__(
        self, initial_entities: Iterable[Any] | None = None, *, deprecated_reason: str | None = None
    ) -> None:
        self.entities: list[Any] = list(initial_entities or [])
        self.deprecated_reason = deprecated_reason
        self.origin = caller_origin()

    def add_action(self, action: Any) -> None:
        self.entities.append(action)

    def add_entity(self, entity: Any) -> None:
        self.entities.append(entity)

    def describe_sub_entities(self) -> list[Any]:
        return list(self.entities)

    def describe(self) -> str:
        return repr(self)

    @property
    def deprecated(self) -> bool:
        return self.deprecated_reason is not None

    def visit(self, context: LaunchContext) -> list[Any] | None:
        if self.deprecated_reason:
            from mlaunch.launch.planning import planner_of  # any context-like object, as upstream

            planner_of(context).warn(f"launch description is deprecated: {self.deprecated_reason}")
        return list(self.entities)

    def get_launch_arguments(self, conditional_inclusion: bool = False) -> list[Any]:
        """The DeclareLaunchArgument actions in this description and in the descriptions it
        includes that load without a context; the first declaration of a name only.

        As upstream's, each gets ``_conditionally_included``: whether something may leave it
        out (its own condition, an enclosing one, a timer or an event handler), as
        ``--show-args`` marks it; ``conditional_inclusion`` says so of this whole description.
        Declarations after a ResetLaunchConfigurations in the same list are not reachable
        from the command line and are left out, as upstream's.
        """
        found = self.get_launch_arguments_with_include_launch_description_actions(
            conditional_inclusion
        )
        return [argument for argument, _ in found]

    def get_launch_arguments_with_include_launch_description_actions(
        self, conditional_inclusion: bool = False
    ) -> list[tuple[Any, list[Any] | None]]:
        """``get_launch_arguments``, each with the includes on the way to it (None: declared in
        this description itself), as upstream's."""
        return declared_arguments(self, conditional_inclusion, files=True)


def declared_arguments(
    description: LaunchDescription, conditional: bool = False, *, files: bool
) -> list[tuple[Any, list[Any] | None]]:
    """The declarations of ``description`` with the includes on the way to each (see
    get_launch_arguments); ``files``: also in the files includes name, loaded without a
    context (an include's check of what it must pass leaves them to their own includes)."""
    found: dict[str, tuple[Any, list[Any] | None]] = {}
    _collect_arguments(description.entities, conditional, found, None, files)
    return list(found.values())


def _collect_arguments(
    entities: Iterable[Any],
    conditional: bool,
    found: dict[str, tuple[Any, list[Any] | None]],
    via: list[Any] | None,
    files: bool,
) -> None:
    """Note in ``found`` the declarations below ``entities`` (see get_launch_arguments)."""
    # launch.actions builds on this module's classes: looked up when asked, not at import.
    from mlaunch.launch.actions.declare_launch_argument import DeclareLaunchArgument
    from mlaunch.launch.actions.include_launch_description import IncludeLaunchDescription
    from mlaunch.launch.actions.register_event_handler import RegisterEventHandler
    from mlaunch.launch.actions.reset_launch_configurations import ResetLaunchConfigurations
    from mlaunch.launch.actions.timer_action import TimerAction
    from mlaunch.launch.walk import children

    for entity in entities:
        if isinstance(entity, DeclareLaunchArgument) and entity.name not in found:
            entity._conditionally_included = conditional or entity.condition is not None
            found[entity.name] = (entity, via)
        if isinstance(entity, ResetLaunchConfigurations):
            return
        inner = conditional or getattr(entity, "condition", None) is not None
        if isinstance(entity, (TimerAction, RegisterEventHandler)):
            # Run only if the timer fires or the event comes: conditional, as in launch.
            later = [e for e, _ in children(entity)]
            _collect_arguments(later, True, found, via, files)
            continue
        if isinstance(entity, IncludeLaunchDescription):
            source = entity.launch_description_source
            described = source.launch_description
            if described is None and files:
                described = source.try_get_launch_description_without_context()
            included = [] if described is None else [described]
            _collect_arguments(included, inner, found, [*(via or ()), entity], files)
            continue
        if not isinstance(entity, LaunchDescriptionEntity):
            continue  # not a launch entity: visiting it says so, where it was written
        _collect_arguments(entity.describe_sub_entities(), inner, found, via, files)
        for _why, more in entity.describe_conditional_sub_entities():
            _collect_arguments(more, True, found, via, files)


__all__ = ["LaunchDescription", "declared_arguments"]
