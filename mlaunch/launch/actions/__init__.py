"""Actions: the launch description, as the same classes and keywords as ROS 2 ``launch.actions``.

An action is data plus ``execute(context)`` (upstream's contract): it reads the context, hands
what must happen at run time to ``context.planner`` as plan steps, and may return entities to
visit next. Nothing here starts a process or prints. The base
classes live in mlaunch.launch.launch_description and ExecuteProcess in
mlaunch.launch.execute_process; both are served from here too, under ROS 2's names.
"""

from __future__ import annotations

import os

from mlaunch.launch.actions.declare_launch_argument import DeclareLaunchArgument
from mlaunch.launch.actions.for_loop import ForEach, ForLoop
from mlaunch.launch.actions.register_event_handler import (
    RegisterEventHandler,
    UnregisterEventHandler,
)
from mlaunch.launch.actions.scoping import (
    GroupAction,
    IncludeLaunchDescription,
    PopEnvironment,
    PopLaunchConfigurations,
    PushEnvironment,
    PushLaunchConfigurations,
    ResetEnvironment,
    ResetLaunchConfigurations,
    SetLaunchConfiguration,
)
from mlaunch.launch.execute_process import ExecuteLocal, ExecuteProcess
from mlaunch.launch.launch_description import Action, LaunchDescription, LaunchDescriptionEntity
from mlaunch.launch.substitutions import (
    normalize,
    perform,
    perform_substitutions,
    to_bool,
)
from mlaunch.plan.errors import LaunchFileError
from mlaunch.plan.origin import caller_origin
from mlaunch.plan.steps import EmitEvent as EmitEventStep
from mlaunch.plan.steps import (
    Log,
    RequestShutdown,
    StartTimer,
)

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable, Iterable
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext
    from mlaunch.launch.substitutions import SomeSubstitutionsType


# --- arguments and configurations ------------------------------------------------------------


class UnsetLaunchConfiguration(Action):
    def __init__(self, name: SomeSubstitutionsType, **kwargs: Any):
        super().__init__(**kwargs)
        self.name = normalize(name)

    def execute(self, context: LaunchContext) -> None:
        context.launch_configurations.pop(perform_substitutions(context, self.name), None)


# --- environment -----------------------------------------------------------------------------


class SetEnvironmentVariable(Action):
    def __init__(self, name: SomeSubstitutionsType, value: SomeSubstitutionsType, **kwargs: Any):
        super().__init__(**kwargs)
        self.name = normalize(name)
        self.value = normalize(value)

    def execute(self, context: LaunchContext) -> None:
        context.environment[perform_substitutions(context, self.name)] = perform_substitutions(
            context, self.value
        )


class UnsetEnvironmentVariable(Action):
    def __init__(self, name: SomeSubstitutionsType, **kwargs: Any):
        super().__init__(**kwargs)
        self.name = normalize(name)

    def execute(self, context: LaunchContext) -> None:
        context.environment.pop(perform_substitutions(context, self.name), None)


class AppendEnvironmentVariable(Action):
    def __init__(
        self,
        name: SomeSubstitutionsType,
        value: SomeSubstitutionsType,
        prepend: Any = False,
        separator: SomeSubstitutionsType = os.pathsep,
        **kwargs: Any,
    ):
        super().__init__(**kwargs)
        self.name = normalize(name)
        self.value = normalize(value)
        self.prepend = prepend
        self.separator = normalize(separator)

    def execute(self, context: LaunchContext) -> None:
        name = perform_substitutions(context, self.name)
        value = perform_substitutions(context, self.value)
        prepend = (
            self.prepend
            if isinstance(self.prepend, bool)
            else to_bool(perform(context, self.prepend), "prepend")
        )
        old = context.environment.get(name)
        sep = perform_substitutions(context, self.separator)
        if not old:
            context.environment[name] = value
        else:
            context.environment[name] = f"{value}{sep}{old}" if prepend else f"{old}{sep}{value}"


# --- structure -------------------------------------------------------------------------------


class OpaqueFunction(Action):
    """Call ``function(context, *args, **kwargs)`` while resolving; visit what it returns."""

    def __init__(
        self,
        *,
        function: Callable[..., Any],
        args: Iterable[Any] | None = None,
        kwargs: dict[str, Any] | None = None,
        **action_kwargs: Any,
    ) -> None:
        super().__init__(**action_kwargs)
        self.function = function
        self.args = list(args or [])
        self.kwargs = dict(kwargs or {})

    def execute(self, context: LaunchContext) -> list[Any] | None:
        planner = context.planner
        result = planner.call_user(self.function, context, *self.args, **self.kwargs)
        return list(result) if result else None

    def describe_short(self) -> str:
        return f"OpaqueFunction({getattr(self.function, '__qualname__', self.function)!r})"


class OpaqueCoroutine(OpaqueFunction):
    """Not supported: mlaunch does not run an asyncio loop for launch files."""

    def __init__(self, *, coroutine: Callable[..., Any], **kwargs: Any) -> None:
        raise LaunchFileError(
            "OpaqueCoroutine is not supported by mlaunch (no asyncio loop runs launch code);"
            " use an OpaqueFunction or a TimerAction",
            where=caller_origin(),
        )


class TimerAction(Action):
    """Resolve and run ``actions`` after ``period`` seconds (cancelled on shutdown by default)."""

    completes_later = True  # ExecutionComplete when it fires (the engine's timer)

    def __init__(
        self,
        *,
        period: float | SomeSubstitutionsType,
        actions: Iterable[Any],
        cancel_on_shutdown: Any = True,
        **kwargs: Any,
    ) -> None:
        super().__init__(**kwargs)
        self.period = period
        self.actions = list(actions)
        self.cancel_on_shutdown = cancel_on_shutdown

    def get_sub_entities(self) -> list[Any]:
        return list(self.actions)

    def execute(self, context: LaunchContext) -> None:
        planner = context.planner
        period = planner.float_value(self.period, "TimerAction period", self.origin)
        cancel = self.cancel_on_shutdown
        if not isinstance(cancel, bool):
            cancel = to_bool(perform(context, cancel), "cancel_on_shutdown")
        planner.add(
            StartTimer(
                origin=self.origin,
                period=period,
                body=planner.defer(self.actions, self.origin),
                cancel_on_shutdown=cancel,
                action=self,
                ros_time=self._ros_time(context),
            )
        )

    def _ros_time(self, context: LaunchContext) -> dict[str, Any] | None:
        """Where the run records whether the period is simulated ROS time (StartTimer's
        ``ros_time``); None: wall-clock time, as launch's TimerAction counts it."""
        return None

    def describe_short(self) -> str:
        return f"TimerAction(period={self.period!r})"


# --- events ----------------------------------------------------------------------------------


class EmitEvent(Action):
    def __init__(self, *, event: Any, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.event = event

    def execute(self, context: LaunchContext) -> list[Any] | None:
        return emit_event_entities(context, self.event, self.origin)


def emit_event_entities(context: LaunchContext, event: Any, origin: str) -> list[Any] | None:
    """Plan the emission of ``event``; the entities to visit now for an include event."""
    from mlaunch.launch.events import IncludeLaunchDescription
    from mlaunch.launch.events import Shutdown as ShutdownEvent

    step: RequestShutdown | EmitEventStep | None = None
    if isinstance(event, ShutdownEvent):
        sigint = bool(event.due_to_sigint)
        step = RequestShutdown(
            origin=origin,
            reason=event.reason,
            due_to_sigint=sigint,
            send_sigint=not sigint or context.noninteractive,
        )
    elif not isinstance(event, IncludeLaunchDescription):
        step = EmitEventStep(origin=origin, event=event)
    context.planner.emit(event, step)
    # An included description is planned here and now, where the event was given.
    return [event.launch_description] if step is None else None


class Shutdown(Action):
    """Shut the launch down (what ``on_exit=Shutdown()`` uses to make a process required)."""

    def __init__(self, *, reason: SomeSubstitutionsType = "reason not given", **kwargs: Any):
        super().__init__(**kwargs)
        self.reason = normalize(reason)

    def execute(self, context: LaunchContext) -> None:
        from mlaunch.launch.events import Shutdown as ShutdownEvent

        reason = perform_substitutions(context, self.reason)
        emit_event_entities(context, ShutdownEvent(reason=reason), self.origin)


class LogInfo(Action):
    def __init__(self, *, msg: SomeSubstitutionsType, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.msg = normalize(msg)

    def execute(self, context: LaunchContext) -> None:
        planner = context.planner
        planner.add(Log(origin=self.origin, message=perform_substitutions(context, self.msg)))


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
