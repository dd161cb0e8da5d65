"""``launch_ros.actions.set_parameter``: a global parameter of the nodes after it; and
``with_use_sim_time`` (``mlaunch --use-sim-time``: the description opened by one).
"""

from __future__ import annotations

from mlaunch.launch.action import Action
from mlaunch.launch.launch_description import LaunchDescription
from mlaunch.launch.substitution import (
    SomeSubstitutionsType,
    describe,
    normalize,
)
from mlaunch.launch_ros import params
from mlaunch.launch_ros.scope import (
    add_global_params,
)

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext
    from mlaunch.launch.launch_description_entity import LaunchDescriptionEntity


def with_use_sim_time(description: LaunchDescriptionEntity, value: bool) -> LaunchDescription:
    """``mlaunch --use-sim-time``: the description opened by ``SetParameter('use_sim_time', ...)``.

    An explicit action placed before the description, so ``use_sim_time`` is the first global
    parameter of every node (a node's own parameters can still override it, as they override
    any SetParameter).
    """
    first = SetParameter("use_sim_time", bool(value))
    first.origin = "--use-sim-time"
    return LaunchDescription([first, description])


class SetParameter(Action):
    """A global parameter for every node after it in this scope (``-p name:=value``)."""

    # mlaunch's: True keeps it inside a scoped group even without --scoped-parameters.
    keep_in_scope = False

    def __init__(self, name: SomeSubstitutionsType, value: Any, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.param_dict = params.normalize_dict({normalize(name): value})
        self._given = (name, value)

    @property
    def name(self) -> Any:
        """launch_ros's: the parameter's name, normalized (a tuple of substitutions)."""
        return next(iter(self._public_dict()))

    @property
    def value(self) -> Any:
        """launch_ros's: the value in launch_ros's normalized shape (see
        launch_ros.utilities.normalize_parameters)."""
        return next(iter(self._public_dict().values()))

    def _public_dict(self) -> dict[Any, Any]:
        from mlaunch.launch_ros.utilities.normalize_parameters import normalize_parameter_dict

        name, value = self._given
        return normalize_parameter_dict({normalize(name): value})

    def execute(self, context: LaunchContext) -> None:
        entries = tuple(params.evaluate_dict(context, self.param_dict).items())
        add_global_params(context, self, entries)

    def describe_short(self) -> str:
        (name,) = self.param_dict
        return f"SetParameter({describe(name)})"
