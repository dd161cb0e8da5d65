"""``launch.launch_description_entity``: ``LaunchDescriptionEntity``, anything that can appear in a
launch description.
"""

from __future__ import annotations

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Iterable
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext


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


def check_entities(entities: list[Any], handler: str) -> None:
    """launch's TypeError for an ``on_*`` list holding something that is not an entity."""
    for entity in entities:
        if not isinstance(entity, LaunchDescriptionEntity):
            raise TypeError(
                f"{handler}: expected all items in the handler's entities to be launch entities"
                f" (actions, descriptions), got {type(entity).__name__}: {entity!r:.60}"
            )
