"""The ``launch`` API of ROS 2, served by mlaunch (see mlaunch.compat).

Launch files import ``launch``, ``launch.actions``, ``launch.substitutions`` ... and get these
modules. The top-level names load on first use, so importing one submodule stays cheap.
"""

from __future__ import annotations

import importlib

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.action import Action
    from mlaunch.launch.condition import Condition
    from mlaunch.launch.event import Event
    from mlaunch.launch.event_handler import EventHandler
    from mlaunch.launch.invalid_launch_file_error import InvalidLaunchFileError
    from mlaunch.launch.launch_context import LaunchContext
    from mlaunch.launch.launch_description import LaunchDescription
    from mlaunch.launch.launch_description_entity import LaunchDescriptionEntity
    from mlaunch.launch.launch_description_source import LaunchDescriptionSource
    from mlaunch.launch.launch_introspector import LaunchIntrospector
    from mlaunch.launch.some_entities_type import SomeEntitiesType, SomeEntitiesType_types_tuple
    from mlaunch.launch.substitution import (
        SomeSubstitutionsType,
        SomeSubstitutionsType_types_tuple,
        Substitution,
        perform_substitutions,
    )

# name -> (module, attribute in it)
_NAMES: dict[str, tuple[str, str]] = {
    "Action": ("mlaunch.launch.action", "Action"),
    "LaunchDescription": ("mlaunch.launch.launch_description", "LaunchDescription"),
    "LaunchDescriptionEntity": (
        "mlaunch.launch.launch_description_entity",
        "LaunchDescriptionEntity",
    ),
    "Condition": ("mlaunch.launch.conditions", "Condition"),
    "InvalidLaunchFileError": (
        "mlaunch.launch.invalid_launch_file_error",
        "InvalidLaunchFileError",
    ),
    "LaunchIntrospector": ("mlaunch.launch.launch_introspector", "LaunchIntrospector"),
    "SomeEntitiesType": ("mlaunch.launch.some_entities_type", "SomeEntitiesType"),
    "SomeEntitiesType_types_tuple": (
        "mlaunch.launch.some_entities_type",
        "SomeEntitiesType_types_tuple",
    ),
    "LaunchContext": ("mlaunch.launch.launch_context", "LaunchContext"),
    "EventHandler": ("mlaunch.launch.event_handlers", "EventHandler"),
    "Event": ("mlaunch.launch.events", "Event"),
    "LaunchDescriptionSource": (
        "mlaunch.launch.launch_description_sources",
        "LaunchDescriptionSource",
    ),
    "SomeSubstitutionsType": ("mlaunch.launch.substitutions", "SomeSubstitutionsType"),
    "SomeSubstitutionsType_types_tuple": (
        "mlaunch.launch.substitutions",
        "SomeSubstitutionsType_types_tuple",
    ),
    "Substitution": ("mlaunch.launch.substitutions", "Substitution"),
    "normalize_to_list_of_substitutions": ("mlaunch.launch.substitutions", "normalize"),
    "perform_substitutions": ("mlaunch.launch.substitutions", "perform_substitutions"),
}

_SUBMODULES = (
    "actions",
    "descriptions",
    "frontend",
    "logging",
    "utilities",
    "substitutions",
    "conditions",
    "event_handlers",
    "events",
    "launch_context",
    "launch_description",
    "launch_description_sources",
)


# Names of the launch API that a higher layer implements (``LaunchService`` runs the engine):
# the application that serves the ROS 2 names adds them with ``provide`` (mlaunch.compat), so
# this layer never imports upward.
_PROVIDED: dict[str, tuple[str, str]] = {}


def provide(name: str, module: str, attribute: str) -> None:
    """Serve ``launch.<name>`` as ``attribute`` of ``module`` (imported on first use)."""
    _PROVIDED[name] = (module, attribute)


def __getattr__(name: str) -> Any:
    if name in _NAMES or name in _PROVIDED:
        module_name, attribute = _NAMES[name] if name in _NAMES else _PROVIDED[name]
        value = getattr(importlib.import_module(module_name), attribute)
        globals()[name] = value
        return value
    if name in _SUBMODULES:
        return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module 'launch' (mlaunch) has no attribute {name!r}")


__all__ = [
    "Action",
    "Condition",
    "Event",
    "EventHandler",
    "InvalidLaunchFileError",
    "LaunchContext",
    "LaunchDescription",
    "LaunchDescriptionEntity",
    "LaunchDescriptionSource",
    "LaunchIntrospector",
    "LaunchService",
    "SomeEntitiesType",
    "SomeEntitiesType_types_tuple",
    "SomeSubstitutionsType",
    "SomeSubstitutionsType_types_tuple",
    "Substitution",
    "normalize_to_list_of_substitutions",
    "perform_substitutions",
]
