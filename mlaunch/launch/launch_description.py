"""The description's building blocks: ``LaunchDescriptionEntity``, ``Action`` and
``LaunchDescription`` (ROS 2's ``launch.action`` and ``launch.launch_description``).

An action is data plus ``execute(context)``, upstream's contract: it reads the context, hands
what must happen at run time to ``context.planner`` as plan steps (mlaunch.plan.planner), and
may return entities to visit next. Nothing here starts a process or prints.
"""

from __future__ import annotations

from mlaunch.plan.origin import caller_origin

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Iterable
    from typing import Any

    from mlaunch.launch.conditions import Condition
    from mlaunch.launch.launch_context import LaunchContext


# The run's state key set once an OnExecutionComplete handler was registered.
COMPLETION_HANDLERS = "completion_handlers"


class LaunchDescriptionEntity:
    """Anything that can appear in a launch description."""

    def visit(self, context: LaunchContext) -> list[Any] | None:
        return None

    def describe_short(self) -> str:
        return type(self).__name__

    # --- introspection, as launch's (LaunchIntrospector reads these) ------------------------

    def describe(self) -> str:
        raise NotImplementedError(f"{type(self).__name__} does not describe itself")

    def describe_sub_entities(self) -> list[Any]:
        """The entities this one always contains."""
        return []

    def describe_conditional_sub_entities(self) -> list[tuple[str, Iterable[Any]]]:
        """(why, entities) for the entities this one contains only under a condition."""
        return []

    def get_asyncio_future(self) -> Any:
        """A future done when this entity's activity ends; mlaunch's entities have none (the
        engine, not an asyncio loop, carries out what they planned)."""
        return None


class Action(LaunchDescriptionEntity):
    """Base of every action: an optional condition and where it was written."""

    def __init__(self, *, condition: Condition | None = None) -> None:
        self.condition = condition
        self.origin = caller_origin()

    # An action whose execution ends later than its visit (a process, a timer) says so itself.
    completes_later = False

    def visit(self, context: LaunchContext) -> list[Any] | None:
        if self.condition is not None and not self.condition.evaluate(context):
            return None
        more = self.execute(context)
        if not self.completes_later and context.run_state.get(COMPLETION_HANDLERS):
            # launch emits ExecutionComplete for every action once it has executed; only
            # when an OnExecutionComplete handler was registered may one be waiting for it.
            from mlaunch.launch.events import ExecutionComplete
            from mlaunch.plan.steps import EmitEvent

            event = ExecutionComplete(action=self)
            context.planner.add(EmitEvent(origin=self.origin, event=event))
        return more

    def execute(self, context: LaunchContext) -> list[Any] | None:
        return None

    def get_sub_entities(self) -> list[Any]:
        return []

    @staticmethod
    def parse(entity: Any, parser: Any) -> tuple[type[Action], dict[str, Any]]:
        """What every tag a package exposes shares (``launch.frontend``): its ``if`` or
        ``unless`` condition, as keyword arguments; subclasses' ``parse`` add their own."""
        from mlaunch.launch.conditions import IfCondition, UnlessCondition

        when = entity.get_attr("if", optional=True)
        unless = entity.get_attr("unless", optional=True)
        if when is not None and unless is not None:
            raise RuntimeError("if and unless conditions can't be used simultaneously")
        kwargs: dict[str, Any] = {}
        if when is not None:
            kwargs["condition"] = IfCondition(parser.parse_substitution(when))
        if unless is not None:
            kwargs["condition"] = UnlessCondition(parser.parse_substitution(unless))
        return Action, kwargs

    def describe(self) -> str:
        return repr(self)

    def describe_sub_entities(self) -> list[Any]:
        return self.get_sub_entities() if self.condition is None else []

    def describe_conditional_sub_entities(self) -> list[tuple[str, Iterable[Any]]]:
        if self.condition is None:
            return []
        return [(f"Conditionally included by {self.describe()}", self.get_sub_entities())]


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
    from mlaunch.launch import actions
    from mlaunch.launch.walk import children

    for entity in entities:
        if isinstance(entity, actions.DeclareLaunchArgument) and entity.name not in found:
            entity._conditionally_included = conditional or entity.condition is not None
            found[entity.name] = (entity, via)
        if isinstance(entity, actions.ResetLaunchConfigurations):
            return
        inner = conditional or getattr(entity, "condition", None) is not None
        if isinstance(entity, (actions.TimerAction, actions.RegisterEventHandler)):
            # Run only if the timer fires or the event comes: conditional, as in launch.
            later = [e for e, _ in children(entity)]
            _collect_arguments(later, True, found, via, files)
            continue
        if isinstance(entity, actions.IncludeLaunchDescription):
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


__all__ = ["Action", "LaunchDescription", "LaunchDescriptionEntity"]
