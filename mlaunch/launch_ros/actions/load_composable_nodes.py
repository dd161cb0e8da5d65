"""``launch_ros.actions.load_composable_nodes``: composable nodes loaded into a running
container; and the request builder launch_ros's helpers and tests call.
"""

from __future__ import annotations

from mlaunch.launch.action import Action
from mlaunch.launch.substitution import Substitution, describe, normalize, perform_substitutions
from mlaunch.launch_ros.actions.composable_node_container import ComposableNodeContainer
from mlaunch.launch_ros.actions.node import node_name_counts
from mlaunch.launch_ros.composition import LoadComponents
from mlaunch.launch_ros.descriptions.composable_node import (
    ComposableNode,
    composable_nodes,
    load_needs,
)
from mlaunch.launch_ros.scope import make_namespace_absolute
from mlaunch.plan.errors import LaunchFileError, MlaunchError
from mlaunch.plan.steps import COMPONENTS, Need

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext


class LoadComposableNodes(Action):
    """Load composable nodes into a container, this launch's or one started elsewhere."""

    def __init__(
        self,
        *,
        composable_node_descriptions: list[ComposableNode],
        target_container: Any,
        **kwargs: Any,
    ) -> None:
        super().__init__(**kwargs)
        if not isinstance(target_container, ComposableNodeContainer):
            if not isinstance(target_container, (str, Substitution, list, tuple)):
                raise LaunchFileError(
                    "target_container must be a ComposableNodeContainer or its name (text or"
                    f" substitutions), got {type(target_container).__name__}:"
                    f" {target_container!r:.80}"
                )
            target_container = normalize(target_container)
        self._target = target_container
        self._descriptions = composable_nodes(composable_node_descriptions)
        self.final_target_container_name: str | None = None

    @property
    def needs(self) -> frozenset[Need]:
        """The LoadNode driver (noted in a timer or a handler body too, before it fires), and
        lifecycle driving when a node autostarts."""
        return load_needs(self._descriptions) | COMPONENTS

    def execute(self, context: LaunchContext) -> None:
        planner = context.planner
        from mlaunch.launch_ros.load_request import load_request

        target = self._target_name()
        if target is None:
            target = perform_substitutions(context, self._target)
        self.final_target_container_name = target
        requests = []
        for description in self._descriptions:
            request = load_request(description, context)
            if request is not None:
                requests.append(request)
        if requests:
            # A relative name is resolved by launch_ros's own node, whose namespace is '/'.
            full = make_namespace_absolute(target) if target else target
            names = node_name_counts(context)
            planner.add(LoadComponents(self.origin, full, tuple(requests), target, names))

    def _target_name(self) -> str | None:
        """The container action's full name (None when the target is given as a name)."""
        if not isinstance(self._target, ComposableNodeContainer):
            return None
        try:
            return self._target.node_name
        except RuntimeError:
            raise MlaunchError(
                f"target_container {self._target.describe_short()} has not been launched yet:"
                " a LoadComposableNodes must come after its container in the launch description"
            )

    def describe_short(self) -> str:
        if isinstance(self._target, ComposableNodeContainer):
            target = self._target.describe_short()
        else:
            target = describe(self._target)
        return f"LoadComposableNodes(target_container={target}, {len(self._descriptions)} nodes)"


def get_composable_node_load_request(composable_node_description: Any, context: Any) -> Any:
    """The ``composition_interfaces`` LoadNode request launch_ros sends for the description in
    ``context`` (the pushed namespace, global remaps and parameters applied); needs the built
    composition_interfaces. A description whose own condition is false has none: ValueError."""
    from mlaunch.launch_ros.load_request import load_request, to_message

    request = load_request(composable_node_description, context)
    if request is None:
        raise ValueError("the composable node's condition is false: it is not loaded")
    return to_message(request)
