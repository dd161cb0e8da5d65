"""The top-level ``launch`` namespace of ROS 2, served by mlaunch (see mlaunch.compat)."""

from __future__ import annotations

import importlib

from mlaunch.actions import Action, LaunchDescription, LaunchDescriptionEntity
from mlaunch.conditions import Condition
from mlaunch.context import LaunchContext
from mlaunch.event_handlers import EventHandler
from mlaunch.events import Event
from mlaunch.launch_description_sources import LaunchDescriptionSource
from mlaunch.substitutions import (
    SomeSubstitutionsType,
    SomeSubstitutionsType_types_tuple,
    Substitution,
    normalize,
    perform_substitutions,
)

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

normalize_to_list_of_substitutions = normalize

_SUBMODULES = {
    "actions": "mlaunch.actions",
    "substitutions": "mlaunch.substitutions",
    "conditions": "mlaunch.conditions",
    "event_handlers": "mlaunch.event_handlers",
    "events": "mlaunch.events",
    "launch_description_sources": "mlaunch.launch_description_sources",
}


def __getattr__(name: str) -> Any:
    if name in _SUBMODULES:
        return importlib.import_module(_SUBMODULES[name])
    raise AttributeError(f"module 'launch' (mlaunch) has no attribute {name!r}")


__all__ = [
    "Action",
    "Condition",
    "Event",
    "EventHandler",
    "LaunchContext",
    "LaunchDescription",
    "LaunchDescriptionEntity",
    "LaunchDescriptionSource",
    "SomeSubstitutionsType",
    "SomeSubstitutionsType_types_tuple",
    "Substitution",
    "normalize_to_list_of_substitutions",
    "perform_substitutions",
]
