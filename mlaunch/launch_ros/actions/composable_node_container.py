"""``launch_ros.actions.composable_node_container``: a component container and the composable
nodes it loads.
"""

from __future__ import annotations

from mlaunch.launch_ros.actions.node import Node
from mlaunch.launch_ros.descriptions.composable_node import (
    ComposableNode,
    composable_nodes,
    load_needs,
)
from mlaunch.plan.steps import Need

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext


class ComposableNodeContainer(Node):
    """A container process (a Node) and the composable nodes to load into it once it is up."""

    def __init__(
        self,
        *,
        name: Any,
        namespace: Any,
        composable_node_descriptions: list[ComposableNode] | None = None,
        **kwargs: Any,
    ) -> None:
        super().__init__(name=name, namespace=namespace, **kwargs)
        self._descriptions = composable_nodes(composable_node_descriptions)

    @property
    def needs(self) -> frozenset[Need]:
        """The LoadNode driver, when there are nodes to load (seen in a timer or handler too),
        and lifecycle driving when one of them autostarts."""
        return load_needs(self._descriptions)

    # A Node returns nothing; a container also returns the load of its nodes (as launch_ros).
    def execute(self, context: LaunchContext) -> list[Any] | None:  # type: ignore[override]
        valid = [
            d
            for d in self._descriptions
            if d.condition() is None or d.condition().evaluate(context)
        ]
        super().execute(context)
        if not valid:
            return None
        from mlaunch.launch_ros.actions.load_composable_nodes import LoadComposableNodes

        load = LoadComposableNodes(composable_node_descriptions=valid, target_container=self)
        load.origin = self.origin
        return [load]
