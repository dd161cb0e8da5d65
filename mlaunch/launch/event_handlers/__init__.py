"""``launch.event_handlers``: what to visit when a process starts, exits, prints, an action
completes or the launch shuts down.

Each handler lives in its own module, named as upstream's; the base class, and how a handler
becomes a step of the plan, is ``launch.event_handler``. This package only gathers the names
(``mlaunch.launch.gathering``).
"""

from __future__ import annotations

from mlaunch.launch.gathering import Gathered

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.launch.event_handler import (
        MATCHER_KIND,
        BaseEventHandler,
        EventHandler,
        returned_entities,
    )
    from mlaunch.launch.event_handlers.on_action_event_base import OnActionEventBase
    from mlaunch.launch.event_handlers.on_execution_complete import OnExecutionComplete
    from mlaunch.launch.event_handlers.on_include_launch_description import (
        OnIncludeLaunchDescription,
    )
    from mlaunch.launch.event_handlers.on_process_exit import OnProcessExit
    from mlaunch.launch.event_handlers.on_process_io import OnProcessIO
    from mlaunch.launch.event_handlers.on_process_start import OnProcessStart
    from mlaunch.launch.event_handlers.on_shutdown import OnShutdown

_gathered = Gathered(
    globals(),
    {
        "BaseEventHandler": "mlaunch.launch.event_handler",
        "EventHandler": "mlaunch.launch.event_handler",
        "MATCHER_KIND": "mlaunch.launch.event_handler",
        "OnActionEventBase": ".on_action_event_base",
        "OnExecutionComplete": ".on_execution_complete",
        "OnIncludeLaunchDescription": ".on_include_launch_description",
        "OnProcessExit": ".on_process_exit",
        "OnProcessIO": ".on_process_io",
        "OnProcessStart": ".on_process_start",
        "OnShutdown": ".on_shutdown",
        "returned_entities": "mlaunch.launch.event_handler",
    },
    submodules=(
        "event_named",
        "on_action_event_base",
        "on_execution_complete",
        "on_include_launch_description",
        "on_process_exit",
        "on_process_io",
        "on_process_start",
        "on_shutdown",
    ),
)
__getattr__ = _gathered.attribute
__dir__ = _gathered.listing

__all__ = [
    "MATCHER_KIND",
    "BaseEventHandler",
    "EventHandler",
    "OnActionEventBase",
    "OnExecutionComplete",
    "OnIncludeLaunchDescription",
    "OnProcessExit",
    "OnProcessIO",
    "OnProcessStart",
    "OnShutdown",
    "event_named",
    "returned_entities",
]
