"""``launch.actions.group_action``: actions in a group, scoped or not.

A scoped group returns its actions between PushLaunchConfigurations/PushEnvironment and
PopEnvironment/PopLaunchConfigurations (a non-forwarding one resets the environment and the
configurations inside, keeping those given), with a SetLaunchConfiguration for each
configuration given; an unscoped group the SetLaunchConfigurations and its actions. Whoever
visits them (the resolver, a unit test) gets the scoping by visiting that list in order.
"""

from __future__ import annotations

from mlaunch.launch.action import Action, placed
from mlaunch.launch.actions.pop_environment import PopEnvironment
from mlaunch.launch.actions.pop_launch_configurations import PopLaunchConfigurations
from mlaunch.launch.actions.push_environment import PushEnvironment
from mlaunch.launch.actions.push_launch_configurations import PushLaunchConfigurations
from mlaunch.launch.actions.reset_environment import ResetEnvironment
from mlaunch.launch.actions.reset_launch_configurations import ResetLaunchConfigurations
from mlaunch.launch.actions.set_launch_configuration import SetLaunchConfiguration
from mlaunch.launch.substitutions.boolean_substitution import bool_value

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Iterable
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext


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
        scoped = bool_value(context, self.scoped, "scoped")
        return self._scoping(scoped, bool_value(context, self.forwarding, "forwarding"))

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
