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
container's full name, which exists only once the container was visited."""

from __future__ import annotations

from mlaunch.plan.steps import COMPONENTS, LIFECYCLE, Handoff, Need

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch_ros.load_request import LoadRequest


class LoadComponents(Handoff):
    """Load ``requests`` into the container ``target`` (a full node name), in order.

    ``written`` is the container's name as the launch file gave it (launch_ros's log lines show
    that, ``'box'`` rather than ``'/box'``); empty means the same as ``target``.
    A Handoff: the supervisor emits it on the record stream when it reaches it (in the plan, a
    timer or an event handler), and the LoadNode driver (mlaunch.parts.components) sends the
    requests; a request with ``autostart`` is then brought up by the lifecycle driver."""

    __slots__ = ("names", "requests", "target", "written")
    _fields = (*Handoff._fields, "target", "requests", "written")

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
    def needs(self) -> frozenset[Need]:
        """The run attaches the LoadNode driver (Plan.needs), and lifecycle driving when a
        request autostarts (a ComposableLifecycleNode's)."""
        if any(r.autostart for r in self.requests):
            return COMPONENTS | LIFECYCLE
        return COMPONENTS

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


__all__ = ["LoadComponents"]
