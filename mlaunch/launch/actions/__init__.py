"""``launch.actions``: the actions of a launch description, as ROS 2's (same classes, keywords and
module names).

An action is data plus ``execute(context)`` (upstream's contract): it reads the context, hands
what must happen at run time to ``context.planner`` as plan steps, and may return entities to
visit next. Each lives in its own module, named as upstream's (``launch.actions.group_action``
...); this package only gathers the names, each module loaded when one of its names is first
asked for (``mlaunch.launch.gathering``). A new action is one new module and one line here.
"""

from __future__ import annotations

from mlaunch.launch.gathering import Gathered

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.launch.action import Action
    from mlaunch.launch.actions.append_environment_variable import AppendEnvironmentVariable
    from mlaunch.launch.actions.declare_launch_argument import DeclareLaunchArgument
    from mlaunch.launch.actions.emit_event import EmitEvent
    from mlaunch.launch.actions.execute_local import ExecuteLocal
    from mlaunch.launch.actions.execute_process import ExecuteProcess
    from mlaunch.launch.actions.for_loop import ForEach, ForLoop
    from mlaunch.launch.actions.group_action import GroupAction
    from mlaunch.launch.actions.include_launch_description import IncludeLaunchDescription
    from mlaunch.launch.actions.log_info import LogInfo
    from mlaunch.launch.actions.opaque_coroutine import OpaqueCoroutine
    from mlaunch.launch.actions.opaque_function import OpaqueFunction
    from mlaunch.launch.actions.pop_environment import PopEnvironment
    from mlaunch.launch.actions.pop_launch_configurations import PopLaunchConfigurations
    from mlaunch.launch.actions.push_environment import PushEnvironment
    from mlaunch.launch.actions.push_launch_configurations import PushLaunchConfigurations
    from mlaunch.launch.actions.register_event_handler import RegisterEventHandler
    from mlaunch.launch.actions.reset_environment import ResetEnvironment
    from mlaunch.launch.actions.reset_launch_configurations import ResetLaunchConfigurations
    from mlaunch.launch.actions.set_environment_variable import SetEnvironmentVariable
    from mlaunch.launch.actions.set_launch_configuration import SetLaunchConfiguration
    from mlaunch.launch.actions.shutdown_action import Shutdown
    from mlaunch.launch.actions.timer_action import TimerAction
    from mlaunch.launch.actions.unregister_event_handler import (
        HandlerNotRegistered as HandlerNotRegistered,
    )
    from mlaunch.launch.actions.unregister_event_handler import UnregisterEventHandler
    from mlaunch.launch.actions.unset_environment_variable import UnsetEnvironmentVariable
    from mlaunch.launch.actions.unset_launch_configuration import UnsetLaunchConfiguration
    from mlaunch.launch.launch_description import LaunchDescription
    from mlaunch.launch.launch_description_entity import LaunchDescriptionEntity

_gathered = Gathered(
    globals(),
    {
        "ForEach": ".for_loop",
        "ForLoop": ".for_loop",
        "Action": "mlaunch.launch.action",
        "AppendEnvironmentVariable": ".append_environment_variable",
        "DeclareLaunchArgument": ".declare_launch_argument",
        "EmitEvent": ".emit_event",
        "ExecuteLocal": ".execute_local",
        "ExecuteProcess": ".execute_process",
        "GroupAction": ".group_action",
        "HandlerNotRegistered": ".unregister_event_handler",
        "IncludeLaunchDescription": ".include_launch_description",
        "LaunchDescription": "mlaunch.launch.launch_description",
        "LaunchDescriptionEntity": "mlaunch.launch.launch_description_entity",
        "LogInfo": ".log_info",
        "OpaqueCoroutine": ".opaque_coroutine",
        "OpaqueFunction": ".opaque_function",
        "PopEnvironment": ".pop_environment",
        "PopLaunchConfigurations": ".pop_launch_configurations",
        "PushEnvironment": ".push_environment",
        "PushLaunchConfigurations": ".push_launch_configurations",
        "RegisterEventHandler": ".register_event_handler",
        "ResetEnvironment": ".reset_environment",
        "ResetLaunchConfigurations": ".reset_launch_configurations",
        "SetEnvironmentVariable": ".set_environment_variable",
        "SetLaunchConfiguration": ".set_launch_configuration",
        "Shutdown": ".shutdown_action",
        "TimerAction": ".timer_action",
        "UnregisterEventHandler": ".unregister_event_handler",
        "UnsetEnvironmentVariable": ".unset_environment_variable",
        "UnsetLaunchConfiguration": ".unset_launch_configuration",
    },
    submodules=(
        "for_loop",
        "append_environment_variable",
        "declare_launch_argument",
        "emit_event",
        "execute_local",
        "execute_process",
        "group_action",
        "include_launch_description",
        "log_info",
        "opaque_coroutine",
        "opaque_function",
        "pop_environment",
        "pop_launch_configurations",
        "push_environment",
        "push_launch_configurations",
        "register_event_handler",
        "reset_environment",
        "reset_launch_configurations",
        "set_environment_variable",
        "set_launch_configuration",
        "shutdown_action",
        "timer_action",
        "unregister_event_handler",
        "unset_environment_variable",
        "unset_launch_configuration",
    ),
)
__getattr__ = _gathered.attribute
__dir__ = _gathered.listing

__all__ = [
    "Action",
    "AppendEnvironmentVariable",
    "DeclareLaunchArgument",
    "EmitEvent",
    "ExecuteLocal",
    "ExecuteProcess",
    "ForEach",
    "ForLoop",
    "GroupAction",
    "HandlerNotRegistered",
    "IncludeLaunchDescription",
    "LaunchDescription",
    "LaunchDescriptionEntity",
    "LogInfo",
    "OpaqueCoroutine",
    "OpaqueFunction",
    "PopEnvironment",
    "PopLaunchConfigurations",
    "PushEnvironment",
    "PushLaunchConfigurations",
    "RegisterEventHandler",
    "ResetEnvironment",
    "ResetLaunchConfigurations",
    "SetEnvironmentVariable",
    "SetLaunchConfiguration",
    "Shutdown",
    "TimerAction",
    "UnregisterEventHandler",
    "UnsetEnvironmentVariable",
    "UnsetLaunchConfiguration",
]
