"""Stand-in for rclcpp_components' containers: ``python -m mlaunch.standins.container ARGS``.

Takes the place of ``component_container``, ``component_container_mt`` and
``component_container_isolated`` on machines without rclcpp. It is an rclpy node (named as the
launch names the container) serving ``~/_container/load_node``, ``~/_container/unload_node``
and ``~/_container/list_nodes`` (composition_interfaces) as the real container does: a loaded
component gets the request's name, namespace, remap rules and parameters, a unique id counting
from 1 and its full name in the response. Extra arguments are read as Jazzy's container reads
them: ``use_intra_process_comms`` and ``forward_global_arguments`` must be booleans (else the
load fails with rclcpp's message), the latter gives the component the container's global
arguments, and any other name is ignored. It hosts in-process the plugins mlaunch has stand-ins
for (``PLUGINS``); any other plugin is refused with success=false and a one-line reason, as
the real container refuses a plugin it cannot find.

rclpy is imported inside main() only, so importing this module stays cheap.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Mapping, Sequence
from typing import TYPE_CHECKING, Any

from mlaunch.standins.common import EXIT_FAILURE, init_ros, spin_until_shutdown

if TYPE_CHECKING:
    from rclpy.node import Node

NODE_NAME = "ComponentManager"


def _robot_state_publisher(node: Node) -> object:
    from mlaunch.standins import rsp

    return rsp.start(node)


# (package, plugin) -> (the default node name of the real component, what starts it on a node).
Plugins = Mapping[tuple[str, str], tuple[str, Callable[["Node"], object]]]
PLUGINS: Plugins = {
    ("robot_state_publisher", "robot_state_publisher::RobotStatePublisher"): (
        "robot_state_publisher",
        _robot_state_publisher,
    ),
}


def refusal(package: str, plugin: str) -> str:
    """The one-line reason a plugin cannot be loaded here."""
    known = ", ".join(sorted(p for _, p in PLUGINS))
    return (
        f"mlaunch's container stand-in cannot load plugin {plugin!r} of package {package!r}"
        f" (rclcpp_components is not installed; the stand-in hosts only: {known})"
    )


# The extra arguments (LoadNode's extra_arguments) rclcpp_components' manager reads in Jazzy,
# each a boolean; it ignores any other name. rclpy has no intra-process transport, so
# use_intra_process_comms is checked and then has no effect here.
EXTRA_ARGUMENTS = ("use_intra_process_comms", "forward_global_arguments")
FORWARD_WARNING = (
    "forward_global_arguments is true by default in nodes, but is not recommended in a"
    " component manager: the component is then influenced by the container's global"
    " arguments, not only those meant for it"
)


def forward_global_arguments(extra_arguments: Sequence[Any]) -> bool:
    """Whether the component takes the container's global arguments (False unless asked).

    Checks the extra arguments as the Jazzy container does: ``use_intra_process_comms`` and
    ``forward_global_arguments`` must be booleans (a ValueError with its message otherwise),
    other names are ignored; the last one given wins.
    """
    from rcl_interfaces.msg import ParameterType

    forward = False
    for argument in extra_arguments:
        if argument.name not in EXTRA_ARGUMENTS:
            continue
        if argument.value.type != ParameterType.PARAMETER_BOOL:
            raise ValueError(f"Extra component argument '{argument.name}' must be a boolean")
        if argument.name == "forward_global_arguments":
            forward = bool(argument.value.bool_value)
    return forward


class Container:
    """The component manager: loaded components by unique id, and the three services."""

    def __init__(self, node: Node, plugins: Plugins = PLUGINS) -> None:
        from composition_interfaces.srv import ListNodes, LoadNode, UnloadNode

        self.node = node
        self.plugins = plugins
        self.components: dict[int, tuple[str, Node, object]] = {}
        self.next_id = 1
        node.create_service(LoadNode, "~/_container/load_node", self.on_load)
        node.create_service(UnloadNode, "~/_container/unload_node", self.on_unload)
        node.create_service(ListNodes, "~/_container/list_nodes", self.on_list)

    def on_load(self, request: Any, response: Any) -> Any:
        key = (request.package_name, request.plugin_name)
        entry = self.plugins.get(key)
        if entry is None:
            response.success = False
            response.error_message = refusal(*key)
            self.node.get_logger().error(response.error_message)
            return response
        default_name, start = entry
        try:
            forward = forward_global_arguments(request.extra_arguments)
        except ValueError as exc:  # as rclcpp's ComponentManagerException: refused, said
            response.success = False
            response.error_message = str(exc)
            self.node.get_logger().error(response.error_message)
            return response
        if forward:
            self.node.get_logger().warning(FORWARD_WARNING)
        try:
            component = self._make_node(request, default_name, forward)
        except Exception as exc:  # rcl refuses bad names, remaps and parameter values
            response.success = False
            response.error_message = f"Component constructor threw an exception: {exc}"
            self.node.get_logger().error(response.error_message)
            return response
        try:
            hosted = start(component)
        except Exception as exc:  # the stand-in's own input checks (a bad URDF...)
            component.destroy_node()
            response.success = False
            response.error_message = f"Component constructor threw an exception: {exc}"
            self.node.get_logger().error(response.error_message)
            return response
        unique_id = self.next_id
        self.next_id += 1
        full_name = component.get_fully_qualified_name()
        self.components[unique_id] = (full_name, component, hosted)
        self.executor.add_node(component)
        self.node.get_logger().info(f"Load Library: {request.plugin_name} (mlaunch stand-in)")
        response.success = True
        response.full_node_name = full_name
        response.unique_id = unique_id
        return response

    def _make_node(self, request: Any, default_name: str, forward: bool) -> Node:
        from rclpy.node import Node
        from rclpy.parameter import Parameter

        # As rclcpp's manager: the name and namespace are local remaps after the request's
        # rules, so they win over the container's own (forward_global_arguments).
        args = ["--ros-args"]
        for rule in request.remap_rules:
            args += ["-r", rule]
        if request.node_name:
            args += ["-r", f"__node:={request.node_name}"]
        if request.node_namespace:
            args += ["-r", f"__ns:={request.node_namespace}"]
        overrides = [Parameter.from_parameter_msg(p) for p in request.parameters]
        return Node(
            default_name,
            context=self.node.context,
            cli_args=args,
            use_global_arguments=forward,
            parameter_overrides=overrides,
            automatically_declare_parameters_from_overrides=False,
        )

    def on_unload(self, request: Any, response: Any) -> Any:
        entry = self.components.pop(request.unique_id, None)
        if entry is None:
            response.success = False
            response.error_message = "No node found with unique_id: " + str(request.unique_id)
            return response
        _, component, _ = entry
        self.executor.remove_node(component)
        component.destroy_node()
        response.success = True
        return response

    def on_list(self, request: Any, response: Any) -> Any:
        response.unique_ids = list(self.components)
        response.full_node_names = [name for name, _, _ in self.components.values()]
        return response

    @property
    def executor(self) -> Any:
        executor = self.node.executor
        assert executor is not None, "the container node spins in an executor"
        return executor


def main(argv: Sequence[str] | None = None, plugins: Plugins = PLUGINS) -> int:
    """Serve the container until shutdown; 1 with one line when composition_interfaces lacks.

    ``plugins`` is what it hosts (a benchmark's container hosts every plugin as a bare node).
    """
    from rclpy.node import Node

    args = [sys.argv[0], *(sys.argv[1:] if argv is None else argv)]
    stop = init_ros(args, NODE_NAME)
    if stop is None:
        return EXIT_FAILURE
    node = Node(NODE_NAME)
    try:
        import composition_interfaces.srv  # noqa: F401
    except ImportError:
        node.get_logger().error(
            "composition_interfaces is not importable: run mlaunch's scripts/setup (it builds"
            " the interfaces) or source a ROS 2 installation"
        )
        return EXIT_FAILURE
    return spin_until_shutdown(node, lambda: Container(node, plugins), {}, stop)


if __name__ == "__main__":
    sys.exit(main())
