#!/usr/bin/env python3
"""Test container hosting a managed (lifecycle) component, for composable_lifecycle_node tests.

    python lifecycle_container.py [--ros-args -r __node:=NAME -r __ns:=NS ...]

No container that ships here hosts a lifecycle component (the real rclcpp_components demos
have none, mlaunch's container stand-in hosts robot_state_publisher's only), so this one does:
it serves ``~/_container/load_node`` and loads the plugin ``mlaunch_test::LifecycleComponent``
as an ``rclpy.lifecycle.Node`` named and namespaced as the request says, in the container's executor;
any other plugin is refused with success=false. Each transition callback of a component prints
one flushed stdout line, ``<full name> transition <label>: success``.
SIGINT/SIGTERM end it with status 0.
"""

from __future__ import annotations

from typing import Any

from _ros_main import main

PLUGIN = "mlaunch_test::LifecycleComponent"


def build(argv: list[str]) -> Any:
    from composition_interfaces.srv import LoadNode
    from rclpy.lifecycle import Node as LifecycleNode
    from rclpy.lifecycle import State, TransitionCallbackReturn
    from rclpy.node import Node

    class Component(LifecycleNode):
        """Reports each transition, then does what rclpy's lifecycle node does by default."""

        def _said(self, label: str, result: TransitionCallbackReturn) -> TransitionCallbackReturn:
            name = self.get_fully_qualified_name()
            print(f"{name} transition {label}: {result.name.lower()}", flush=True)
            return result

        def on_configure(self, state: State) -> TransitionCallbackReturn:
            return self._said("configure", super().on_configure(state))

        def on_activate(self, state: State) -> TransitionCallbackReturn:
            return self._said("activate", super().on_activate(state))

        def on_deactivate(self, state: State) -> TransitionCallbackReturn:
            return self._said("deactivate", super().on_deactivate(state))

    container = Node("lifecycle_container")
    hosted: list[Any] = []

    def on_load(request: Any, response: Any) -> Any:
        if request.plugin_name != PLUGIN:
            response.success = False
            response.error_message = f"the lifecycle test container hosts only {PLUGIN}"
            return response
        args = ["--ros-args", "-r", f"__node:={request.node_name or 'lifecycle_component'}"]
        if request.node_namespace:
            args += ["-r", f"__ns:={request.node_namespace}"]
        component = Component("lifecycle_component", context=container.context, cli_args=args)
        hosted.append(component)
        executor = container.executor
        assert executor is not None, "the container spins in an executor"
        executor.add_node(component)
        response.success = True
        response.full_node_name = component.get_fully_qualified_name()
        response.unique_id = len(hosted)
        return response

    container.create_service(LoadNode, "~/_container/load_node", on_load)
    return container


if __name__ == "__main__":
    main(build)
