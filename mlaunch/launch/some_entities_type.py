"""``launch.some_entities_type``: what launch accepts where it takes entities."""

from collections.abc import Iterable

from mlaunch.launch.launch_description_entity import LaunchDescriptionEntity

SomeEntitiesType = LaunchDescriptionEntity | Iterable[LaunchDescriptionEntity]
SomeEntitiesType_types_tuple = (LaunchDescriptionEntity, Iterable)

__all__ = ["SomeEntitiesType", "SomeEntitiesType_types_tuple"]
