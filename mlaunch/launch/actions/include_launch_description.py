"""``launch.actions.include_launch_description``: another launch file, with arguments.

An include returns a SetLaunchConfiguration for each argument given, then the included
description. Before returning, it checks that each argument the description requires is given,
and points the locals (ThisLaunchFile, ThisLaunchFileDir ...) at the included file, as Jazzy's
does, for the arguments and what follows too (mlaunch.launch.file_locals; opt-in: the
includer's). The planner is told which description is the included file's
(``Planner.include``): the resolver visits it in the chain of includes (a cycle is an error)
with the file's locals.
"""

from __future__ import annotations

from mlaunch.launch.action import Action, placed
from mlaunch.launch.actions.pop_environment import PopEnvironment
from mlaunch.launch.actions.pop_launch_configurations import PopLaunchConfigurations
from mlaunch.launch.actions.push_environment import PushEnvironment
from mlaunch.launch.actions.push_launch_configurations import PushLaunchConfigurations
from mlaunch.launch.actions.set_launch_configuration import SetLaunchConfiguration
from mlaunch.launch.substitution import perform
from mlaunch.plan.errors import LaunchArgumentError

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Iterable
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext


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
        from mlaunch.launch.launch_description_source import LaunchDescriptionSource
        from mlaunch.launch.launch_description_sources.any_launch_description_source import (
            source_for,
        )

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
