"""``launch.actions.declare_launch_argument``: a launch argument of the description."""

from __future__ import annotations

from mlaunch.launch.action import Action
from mlaunch.launch.substitution import TextSubstitution, normalize, perform_substitutions
from mlaunch.plan.errors import LaunchArgumentError
from mlaunch.plan.steps import ArgumentInfo

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Iterable
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext
    from mlaunch.launch.substitution import SomeSubstitutionsType


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
        # A list, as upstream's normalized substitutions read back.
        self.default_value = None if default_value is None else list(normalize(default_value))
        # A list, as upstream's DeclareLaunchArgument.choices reads back.
        self.choices = None if choices is None else [str(c) for c in choices]
        if self.choices is not None and not self.choices:
            raise LaunchArgumentError(
                f"argument {name!r} declares an empty list of choices", where=self.origin
            )
        # A plain text default is known now: one outside the choices is refused at once.
        plain = isinstance(default_value, str)
        if self.choices is not None and plain and default_value not in self.choices:
            raise LaunchArgumentError(
                f"argument {name!r}: the default value {default_value!r} is not in provided"
                f" choices {self.choices}",
                where=self.origin,
            )
        if description is None:
            description = (
                f"One of: {list(self.choices)}" if self.choices else "no description given"
            )
        elif self.choices:
            sep = "" if description.endswith(".") else "."
            description = f"{description}{sep} Valid choices are: {list(self.choices)}"
        self.description = description
        # Whether it is declared only under a condition, as the description's
        # get_launch_arguments found it (what an include's check of required arguments reads).
        self._conditionally_included = False

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
                    f"Required launch argument {self.name!r} was not provided"
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


__all__ = ["DeclareLaunchArgument"]
