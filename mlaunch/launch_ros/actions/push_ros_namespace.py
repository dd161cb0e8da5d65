"""``launch_ros.actions.push_ros_namespace``: push a ROS namespace for the nodes after it."""

from __future__ import annotations

from mlaunch.launch.action import Action
from mlaunch.launch.substitution import (
    SomeSubstitutionsType,
    describe,
    normalize,
    perform_substitutions,
)
from mlaunch.launch_ros.scope import (
    namespace_problem,
    prefix_namespace,
)
from mlaunch.plan.errors import SubstitutionFailure

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext


class PushROSNamespace(Action):
    """Push a ROS namespace: nodes after it (in this scope) live under it; relative ones nest."""

    def __init__(self, namespace: SomeSubstitutionsType, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.namespace = normalize(namespace)

    def execute(self, context: LaunchContext) -> None:
        pushed = perform_substitutions(context, self.namespace)
        previous = context.launch_configurations.get("ros_namespace")
        combined = prefix_namespace(previous, pushed)
        assert combined is not None
        problem = namespace_problem(combined)
        if problem is not None:
            raise SubstitutionFailure(
                f"the resulting namespace {combined!r} is invalid: {problem}"
                f" [previous_namespace={previous!r}, pushed_namespace={pushed!r}]"
            )
        context.launch_configurations["ros_namespace"] = combined

    def describe_short(self) -> str:
        return f"PushROSNamespace({describe(self.namespace)})"


PushRosNamespace = PushROSNamespace
