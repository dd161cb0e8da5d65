"""``ComposableNodeContainer`` and ``LoadComposableNodes`` (launch_ros.actions), resolved.

A container is a Node process. Its composable nodes, and those of a LoadComposableNodes, become
one ``LoadComponents`` plan step: the container's full name and the LoadNode requests, built
when the action is visited (so in the scope it was written in: pushed namespace, global
parameters and remaps), in launch_ros's order. The step is what ``--print`` shows and what the
LoadNode driver sends, one request after the other, once ``<container>/_container/load_node``
is available.

launch_ros rules kept: a container's nodes whose condition is false are dropped when the
container is visited (and each condition is evaluated again when its request is built); a
``target_container`` given as a name is used as written (not prefixed with the pushed
namespace; a relative name resolves against '/'); given as a container action it is that
container's full name, which exists only once the container was visited.
"""

from __future__ import annotations

from mlaunch.launch.actions import Action
from mlaunch.launch.substitutions import Substitution, describe, normalize, perform_substitutions
from mlaunch.launch_ros.actions import Node, make_namespace_absolute
from mlaunch.launch_ros.composable import ComposableNode
from mlaunch.launch_ros.node import node_name_counts
from mlaunch.plan.errors import LaunchFileError, MlaunchError
from mlaunch.plan.steps import COMPONENTS, NO_NEEDS, Handoff, Need

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext
    from mlaunch.launch_ros.load_request import LoadRequest


class LoadComponents(Handoff):
    """Load ``requests`` into the container ``target`` (a full node name), in order.

    ``written`` is the container's name as the launch file gave it (launch_ros's log lines show
    that, ``'box'`` rather than ``'/box'``); empty means the same as ``target``.
    A Handoff: the supervisor emits it on the event stream when it reaches it (in the plan, a
    timer or an event handler), and the LoadNode driver (mlaunch.parts.components) sends the
    requests."""

    __slots__ = ("names", "requests", "target", "written")
    _fields = (*Handoff._fields, "target", "requests", "written")
    needs = COMPONENTS  # the run attaches the LoadNode driver (Plan.needs)

    def __init__(
        self,
        origin: str = "",
        target: str = "",
        requests: tuple[LoadRequest, ...] = (),
        written: str = "",
        names: dict[str, int] | None = None,
    ) -> None:
        self.origin = origin
        self.target = target
        self.requests = requests
        self.written = written
        # The run's count of node names (launch_ros's), which a load adds to once it succeeds;
        # not a field: it is the run's shared state, not what the step says.
        self.names = names

    @property
    def container_name(self) -> str:
        """The container as launch_ros names it in its log lines: as written in the file."""
        return self.written or self.target

    @property
    def service(self) -> str:
        """The LoadNode service of the container."""
        return f"{self.target}/_container/load_node"

    def component_names(self) -> list[str]:
        """Full names of the components to load whose name is given (``mlaunch test`` expects
        them in the graph; a component named by its container is not known in advance)."""
        return [r.full_name for r in self.requests if r.node_name]

    def describe_lines(self) -> list[str]:
        """--print: each component with its container, plugin, name, params and remaps."""
        from mlaunch.launch_ros.load_request import describe_request

        lines = []
        for request in self.requests:
            lines.extend(describe_request(request, self.target, self.origin))
        return lines

    def describe_data(self) -> dict[str, Any]:
        """--print --format json: the container and each component to load, in order."""
        from mlaunch.launch_ros.load_request import request_data

        return {
            "kind": "load_components",
            "container": self.target,
            "nodes": [request_data(r) for r in self.requests],
        }


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
        self._descriptions = _descriptions(composable_node_descriptions)

    @property
    def needs(self) -> frozenset[Need]:
        """The LoadNode driver, when there are nodes to load (seen in a timer or handler too)."""
        return COMPONENTS if self._descriptions else NO_NEEDS

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
        load = LoadComposableNodes(composable_node_descriptions=valid, target_container=self)
        load.origin = self.origin
        return [load]


class LoadComposableNodes(Action):
    """Load composable nodes into a container, this launch's or one started elsewhere."""

    needs = COMPONENTS  # noted in a timer or a handler body too, before it fires

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
        self._descriptions = _descriptions(composable_node_descriptions)
        self.final_target_container_name: str | None = None

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


def _descriptions(descriptions: Any) -> list[ComposableNode]:
    if descriptions is None:
        return []
    if isinstance(descriptions, (str, ComposableNode)) or not hasattr(descriptions, "__iter__"):
        raise LaunchFileError(
            "composable_node_descriptions must be a list of ComposableNode, got"
            f" {type(descriptions).__name__}: {descriptions!r:.80}"
        )
    out = list(descriptions)
    for d in out:
        if not isinstance(d, ComposableNode):
            raise LaunchFileError(
                "composable_node_descriptions must hold ComposableNode descriptions"
                f" (launch_ros.descriptions.ComposableNode), got {type(d).__name__}: {d!r:.80}"
            )
    return out


__all__ = ["ComposableNodeContainer", "LoadComponents", "LoadComposableNodes"]
