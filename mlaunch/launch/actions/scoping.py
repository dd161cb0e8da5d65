"""Scoping: launch configurations and the environment, and the two actions that scope others.

GroupAction and IncludeLaunchDescription return, as upstream's, the actions that do their
scoping for the caller to visit in order (Push/Pop of the configurations and the environment,
SetLaunchConfiguration, the Reset actions, the included description); those actions live here
too. One module for all of them: each is small, and they are on the path to the first child
(upstream's module names, ``launch.actions.group_action`` ..., re-export them).

A group (``GroupAction``): a scoped group returns its actions between
PushLaunchConfigurations/PushEnvironment and PopEnvironment/PopLaunchConfigurations (a
non-forwarding one resets the environment and the configurations inside, keeping those given),
with a SetLaunchConfiguration for each configuration given; an unscoped group the
SetLaunchConfigurations and its actions.

An include (``IncludeLaunchDescription``) returns a SetLaunchConfiguration for each argument
given, then the included description. Before returning, it checks that each argument the
description requires is given, and points the locals (ThisLaunchFile, ThisLaunchFileDir ...) at
the included file, as Jazzy's does, for the arguments and what follows too (mlaunch.launch.
file_locals; opt-in: the includer's). The planner is told which description is the included
file's (``Planner.include``): the resolver visits it in the chain of includes (a cycle is an
error) with the file's locals.

The stack of scopes: mlaunch's context keeps one stack, each entry the configurations and the
environment together (``LaunchContext.push_scope``). PushLaunchConfigurations and
PushEnvironment each push one; PopLaunchConfigurations takes the top one back for the
configurations only and PopEnvironment for the environment only, so each pair restores just its
own half, as upstream's two stacks do when pairs nest (a group returns them nested). Pairs that
cross (pushing one kind, then the other, and popping the first first) restore what the other
push kept.
"""

from __future__ import annotations

from mlaunch.launch.launch_description import Action
from mlaunch.launch.substitutions import normalize, perform, perform_substitutions, to_bool
from mlaunch.plan.errors import LaunchArgumentError

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Iterable
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext
    from mlaunch.launch.substitutions import SomeSubstitutionsType


class SetLaunchConfiguration(Action):
    """Set the configuration ``name`` to ``value``, both performed when it is visited."""

    def __init__(self, name: SomeSubstitutionsType, value: SomeSubstitutionsType, **kwargs: Any):
        super().__init__(**kwargs)
        self.name = normalize(name)
        self.value = normalize(value)

    def execute(self, context: LaunchContext) -> None:
        name = perform_substitutions(context, self.name)
        context.launch_configurations[name] = perform_substitutions(context, self.value)


class PushLaunchConfigurations(Action):
    """Keep the launch configurations as they are now, for the matching Pop to restore."""

    def execute(self, context: LaunchContext) -> None:
        context.push_scope()


class PushEnvironment(Action):
    """Keep the environment as it is now (one scope of the context: see the module
    docstring)."""

    def execute(self, context: LaunchContext) -> None:
        context.push_scope()


class PopLaunchConfigurations(Action):
    """Restore the launch configurations the matching PushLaunchConfigurations kept; the
    environment stays as it is (see the module docstring)."""

    def execute(self, context: LaunchContext) -> None:
        environment = dict(context.environment)  # a copy: a context on os.environ pops in place
        context.pop_scope()
        context.environment = environment


class PopEnvironment(Action):
    """Restore the environment the matching PushEnvironment kept; the launch configurations
    stay as they are (see the module docstring)."""

    def execute(self, context: LaunchContext) -> None:
        configurations = context.launch_configurations
        context.pop_scope()
        context.launch_configurations = configurations


class ResetEnvironment(Action):
    """Forget every change made to the environment (what a non-forwarding group starts with)."""

    def execute(self, context: LaunchContext) -> None:
        context.environment = dict(context.initial_environment)


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


class GroupAction(Action):
    """Actions in a scope: by default configuration and environment changes stay inside.

    ``scoped`` and ``forwarding`` are booleans, or (mlaunch, from markup) substitutions
    performed to one when the group is visited.
    """

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
        self._returned: list[Any] | None = None  # built once, as upstream's

    def get_sub_entities(self) -> list[Any]:
        """What a visit returns; with flags written as substitutions, the actions alone (how
        they are scoped is known only when the group is visited)."""
        if not isinstance(self.scoped, bool) or not isinstance(self.forwarding, bool):
            return list(self.actions)
        if self._returned is None:
            self._returned = self._scoping(self.scoped, self.forwarding)
        return list(self._returned)

    def execute(self, context: LaunchContext) -> list[Any]:
        if isinstance(self.scoped, bool) and isinstance(self.forwarding, bool):
            return self.get_sub_entities()
        scoped = _flag(context, self.scoped, "scoped")
        return self._scoping(scoped, _flag(context, self.forwarding, "forwarding"))

    def _scoping(self, scoped: bool, forwarding: bool) -> list[Any]:
        """The actions between what scopes them (see the module docstring)."""
        configs = self.launch_configurations
        sets: list[Action] = [SetLaunchConfiguration(k, v) for k, v in configs.items()]
        if not scoped:
            return [*placed(sets, self.origin), *self.actions]
        if not forwarding:  # the kept values are performed before the configurations are reset
            sets = [ResetEnvironment(), ResetLaunchConfigurations(configs)]
        opening = [PushLaunchConfigurations(), PushEnvironment(), *sets]
        closing = [PopEnvironment(), PopLaunchConfigurations()]
        return [*placed(opening, self.origin), *self.actions, *placed(closing, self.origin)]


def placed(actions: list[Action], origin: str) -> list[Action]:
    """``actions`` (made by a group or an include to scope what it holds) located where that
    was written: what an error in one of them names."""
    for action in actions:
        action.origin = origin
    return actions


def _flag(context: LaunchContext, value: Any, what: str) -> bool:
    return value if isinstance(value, bool) else to_bool(perform(context, value), what)


class IncludeLaunchDescription(Action):
    """Another launch file (any format), with arguments; not scoped, as in ROS 2.

    ``scoped=True`` (an mlaunch extension, like rolling's ScopedIncludeLaunchDescription) keeps
    the included file's configurations and environment changes from leaking out.
    """

    # mlaunch's: True keeps the file locals to the include (its arguments and the actions after
    # it get the includer's) even without --scoped-file-locals: ROS 1 files' includes.
    keep_file_locals = False

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

    def get_sub_entities(self) -> list[Any]:
        """The included description when it is known without a context."""
        found = self.launch_description_source.try_get_launch_description_without_context()
        return [] if found is None else [found]

    def execute(self, context: LaunchContext) -> list[Any]:
        from mlaunch.launch import file_locals

        planner = context.planner
        source = self.launch_description_source
        path = source.get_launch_file_location(context)
        description = planner.load_source(source, origin=self.origin)
        included = file_locals.of_location(source.expand_location(context))
        scoped = file_locals.is_scoped(context, self)
        planner.include(description, path, self.origin, included, scoped)
        if not scoped:  # Jazzy: the arguments, and what follows the include, see the file's
            file_locals.point_at(context, included)
        self._check_required(
            description, [perform(context, name) for name, _ in self.launch_arguments]
        )
        sets: list[Action] = [SetLaunchConfiguration(k, v) for k, v in self.launch_arguments]
        if not self.scoped:
            return [*placed(sets, self.origin), description]
        opening = [PushLaunchConfigurations(), PushEnvironment(), *sets]
        closing = [PopEnvironment(), PopLaunchConfigurations()]
        return [*placed(opening, self.origin), description, *placed(closing, self.origin)]

    def _check_required(self, description: Any, given: list[str]) -> None:
        """Each argument the description declares without a default (not under a condition)
        must be given by this include, or by an include inside it on the way to it."""
        from mlaunch.launch.launch_description import LaunchDescription, declared_arguments

        if not isinstance(description, LaunchDescription):  # an entity a source made
            return
        for argument, includes in declared_arguments(description, files=False):
            if argument._conditionally_included or argument.default_value is not None:
                continue
            names = list(given)
            for include in includes or ():
                names.extend(include.argument_names_without_context())
            if argument.name not in names:
                raise LaunchArgumentError(
                    f"Included launch description missing required argument {argument.name!r}"
                    f" ({argument.description}); the include gives: [{', '.join(names)}]",
                    where=self.origin,
                )

    def argument_names_without_context(self) -> list[str]:
        """The names of the arguments this include gives, those a bare context can perform."""
        from mlaunch.launch.launch_context import LaunchContext
        from mlaunch.plan.errors import MlaunchError

        context = LaunchContext()
        names = []
        for name, _ in self.launch_arguments:
            try:
                names.append(perform(context, name))
            except (MlaunchError, LookupError, ValueError):
                continue
        return names

    def describe_short(self) -> str:
        return f"IncludeLaunchDescription({self.launch_description_source.describe()})"


__all__ = [
    "GroupAction",
    "IncludeLaunchDescription",
    "PopEnvironment",
    "PopLaunchConfigurations",
    "PushEnvironment",
    "PushLaunchConfigurations",
    "ResetEnvironment",
    "ResetLaunchConfigurations",
    "SetLaunchConfiguration",
    "placed",
]
