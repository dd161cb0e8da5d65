"""Actions: the launch description, as the same classes and keywords as ROS 2 ``launch.actions``.

An action is data plus ``execute(context)`` (upstream's contract): it reads the context, hands
what must happen at run time to ``context.planner`` as plan steps, and may return entities to
visit next. Nothing here starts a process or prints. The base
classes live in mlaunch.launch.launch_description and ExecuteProcess in
mlaunch.launch.execute_process; both are served from here too, under ROS 2's names.
"""

from __future__ import annotations

import os

from mlaunch.launch.event_handlers import register_step
from mlaunch.launch.execute_process import ExecuteLocal, ExecuteProcess
from mlaunch.launch.launch_description import Action, LaunchDescription, LaunchDescriptionEntity
from mlaunch.launch.substitutions import (
    TextSubstitution,
    normalize,
    perform,
    perform_substitutions,
    to_bool,
)
from mlaunch.plan.errors import LaunchArgumentError, LaunchFileError
from mlaunch.plan.origin import caller_origin
from mlaunch.plan.steps import (
    ArgumentInfo,
    Log,
    RemoveHandler,
    RequestShutdown,
    StartTimer,
)
from mlaunch.plan.steps import EmitEvent as EmitEventStep

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable, Iterable
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext
    from mlaunch.launch.substitutions import SomeSubstitutionsType


# --- arguments and configurations ------------------------------------------------------------


class DeclareLaunchArgument(Action):
    """A launch argument: the command line or an includer may set it, else its default applies."""

    def __init__(
        self,
        name: str,
        *,
        default_value: SomeSubstitutionsType | None = None,
        description: str | None = None,
        choices: Iterable[str] | None = None,
        **kwargs: Any,
    ) -> None:
        super().__init__(**kwargs)
        self.name = name
        self._conditionally_included = False  # LaunchDescription.get_launch_arguments sets it
        self.default_value = None if default_value is None else normalize(default_value)
        # A list, as upstream's DeclareLaunchArgument.choices reads back.
        self.choices = None if choices is None else [str(c) for c in choices]
        if self.choices is not None and not self.choices:
            raise LaunchArgumentError(
                f"argument {name!r} declares an empty list of choices", where=self.origin
            )
        if description is None:
            description = (
                f"One of: {list(self.choices)}" if self.choices else "no description given"
            )
        elif self.choices:
            sep = "" if description.endswith(".") else "."
            description = f"{description}{sep} Valid choices are: {list(self.choices)}"
        self.description = description

    def argument_info(self, conditional: bool) -> ArgumentInfo:
        default = None
        if self.default_value is not None:
            default = " + ".join(
                s.text if isinstance(s, TextSubstitution) else s.describe()
                for s in self.default_value
            )
        return ArgumentInfo(
            name=self.name,
            default=default,
            description=self.description,
            choices=None if self.choices is None else tuple(self.choices),
            origin=self.origin,
            conditional=conditional or self.condition is not None,
        )

    def execute(self, context: LaunchContext) -> None:
        planner = context.planner
        info = planner.declare_argument(self.argument_info(conditional=False))
        if self.name not in context.launch_configurations:
            if self.default_value is None:
                raise LaunchArgumentError(
                    f"required launch argument {self.name!r} was not provided"
                    f" (pass {self.name}:=<value>)"
                    + (f"; valid choices: {', '.join(self.choices)}" if self.choices else ""),
                    where=self.origin,
                )
            context.launch_configurations[self.name] = perform_substitutions(
                context, self.default_value
            )
        value = context.launch_configurations[self.name]
        if self.choices is not None and value not in self.choices:
            raise LaunchArgumentError(
                f"argument {self.name!r} got {value!r}, which is not one of its choices:"
                f" {', '.join(self.choices)}",
                where=self.origin,
            )
        if info.value is None:  # the first declaration's value, as --print --format json shows
            info.value = str(value)

    def describe_short(self) -> str:
        return f"DeclareLaunchArgument({self.name!r})"


class SetLaunchConfiguration(Action):
    def __init__(self, name: SomeSubstitutionsType, value: SomeSubstitutionsType, **kwargs: Any):
        super().__init__(**kwargs)
        self.name = normalize(name)
        self.value = normalize(value)

    def execute(self, context: LaunchContext) -> None:
        name = perform_substitutions(context, self.name)
        context.launch_configurations[name] = perform_substitutions(context, self.value)


class UnsetLaunchConfiguration(Action):
    def __init__(self, name: SomeSubstitutionsType, **kwargs: Any):
        super().__init__(**kwargs)
        self.name = normalize(name)

    def execute(self, context: LaunchContext) -> None:
        context.launch_configurations.pop(perform_substitutions(context, self.name), None)


class PushLaunchConfigurations(Action):
    def execute(self, context: LaunchContext) -> None:
        context.push_scope()


class PopLaunchConfigurations(Action):
    def execute(self, context: LaunchContext) -> None:
        context.pop_scope()


PushEnvironment = PushLaunchConfigurations
PopEnvironment = PopLaunchConfigurations


class ResetLaunchConfigurations(Action):
    """Forget every configuration, then set the given ones (performed before forgetting)."""

    def __init__(self, launch_configurations: dict[Any, Any] | None = None, **kwargs: Any):
        super().__init__(**kwargs)
        self.launch_configurations = launch_configurations or {}

    def execute(self, context: LaunchContext) -> None:
        keep = {
            perform(context, k): perform(context, v) for k, v in self.launch_configurations.items()
        }
        context.launch_configurations = keep


class ResetEnvironment(Action):
    def execute(self, context: LaunchContext) -> None:
        context.environment = dict(context.initial_environment)


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


class GroupAction(Action):
    """Actions in a scope: by default configuration and environment changes stay inside."""

    def __init__(
        self,
        actions: Iterable[Any],
        *,
        scoped: Any = True,
        forwarding: Any = True,
        launch_configurations: dict[Any, Any] | None = None,
        **kwargs: Any,
    ) -> None:
        super().__init__(**kwargs)
        self.actions = list(actions)
        self.scoped = scoped
        self.forwarding = forwarding
        self.launch_configurations = launch_configurations or {}

    def get_sub_entities(self) -> list[Any]:
        return list(self.actions)

    def _flag(self, ctx: LaunchContext, value: Any, what: str) -> bool:
        return value if isinstance(value, bool) else to_bool(perform(ctx, value), what)

    def execute(self, context: LaunchContext) -> None:
        planner = context.planner
        configs = {
            perform(context, k): perform(context, v) for k, v in self.launch_configurations.items()
        }
        if not self._flag(context, self.scoped, "scoped"):
            context.launch_configurations.update(configs)
            planner.visit_all(self.actions)
            return
        with context.scope(
            forwarding=self._flag(context, self.forwarding, "forwarding"), configs=configs
        ):
            planner.visit_all(self.actions)


class IncludeLaunchDescription(Action):
    """Another launch file (any format), with arguments; not scoped, as in ROS 2.

    ``scoped=True`` (an mlaunch extension, like rolling's ScopedIncludeLaunchDescription) keeps
    the included file's configurations and environment changes from leaking out.
    """

    def __init__(
        self,
        launch_description_source: Any,
        *,
        launch_arguments: Iterable[tuple[Any, Any]] | dict[Any, Any] | None = None,
        scoped: bool = False,
        **kwargs: Any,
    ) -> None:
        super().__init__(**kwargs)
        from mlaunch.launch.launch_description_sources import LaunchDescriptionSource, source_for

        if not isinstance(launch_description_source, LaunchDescriptionSource):
            launch_description_source = source_for(launch_description_source)
        self.launch_description_source = launch_description_source
        if isinstance(launch_arguments, dict):
            launch_arguments = list(launch_arguments.items())
        self.launch_arguments = list(launch_arguments or [])
        self.scoped = scoped

    def execute(self, context: LaunchContext) -> None:
        planner = context.planner
        source = self.launch_description_source
        path = source.get_launch_file_location(context)
        args = [(perform(context, k), perform(context, v)) for k, v in self.launch_arguments]
        description = planner.load_source(source, origin=self.origin)
        if self.scoped:
            context.push_scope()
        try:
            for name, value in args:
                context.launch_configurations[name] = value
            if path is None:
                planner.visit(description)
            else:
                with planner.including(path, self.origin), context.file_locals(path):
                    planner.visit(description)
        finally:
            if self.scoped:
                context.pop_scope()

    def describe_short(self) -> str:
        return f"IncludeLaunchDescription({self.launch_description_source.describe()})"


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
            )
        )

    def describe_short(self) -> str:
        return f"TimerAction(period={self.period!r})"


# --- events ----------------------------------------------------------------------------------


class RegisterEventHandler(Action):
    def __init__(self, event_handler: Any, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.event_handler = event_handler

    def execute(self, context: LaunchContext) -> None:
        handler = self.event_handler
        step = register_step(context, handler, self.origin)
        if step is None:
            raise LaunchFileError(
                f"event handler {type(handler).__name__} is not supported by mlaunch",
                where=self.origin,
            )
        context.planner.add(step)


class UnregisterEventHandler(Action):
    def __init__(self, event_handler: Any, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.event_handler = event_handler

    def execute(self, context: LaunchContext) -> None:
        planner = context.planner
        planner.add(RemoveHandler(origin=self.origin, handler=self.event_handler))


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
        step = RequestShutdown(origin=origin, reason=event.reason)
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
