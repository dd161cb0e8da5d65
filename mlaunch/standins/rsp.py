"""Stand-in for robot_state_publisher: ``python -m mlaunch.standins.rsp [--ros-args ...]``.

It takes the real node's parameters, refuses an invalid URDF the way the real one does (but with a
one-line message and exit status 1), latches the URDF on ``robot_description`` for late
subscribers (the simulator, joint_state_publisher and the viewer read it there) and follows
``joint_states``. There is no tf2_msgs wheel here, so /tf and /tf_static are not published.
rclpy is imported inside main() only, so importing this module stays cheap.
"""

from __future__ import annotations

import sys
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from mlaunch.standins.common import EXIT_FAILURE, init_ros, spin_until_shutdown
from mlaunch.standins.urdf import Robot, UrdfError, parse_urdf

if TYPE_CHECKING:
    from rclpy.node import Node
    from rclpy.parameter import Parameter
    from rclpy.publisher import Publisher
    from sensor_msgs.msg import JointState

NODE_NAME = "robot_state_publisher"


class ParameterError(ValueError):
    """A parameter has a value the node cannot use; the message names it and the bad value."""


# Bad input the node refuses with one line (and exit status 1), as the real one does.
INPUT_ERRORS: dict[type[Exception], str] = {
    UrdfError: "robot_description is not a valid URDF: ",
    ParameterError: "",
}


@dataclass(frozen=True)
class ParamSpec:
    """One parameter the real node declares: its name, default and the Python type it must be."""

    name: str
    default: Any
    kind: type


PARAMS = (
    ParamSpec("robot_description", "", str),
    ParamSpec("publish_frequency", 20.0, float),
    ParamSpec("ignore_timestamp", False, bool),
    ParamSpec("frame_prefix", "", str),
)


def coerce(spec: ParamSpec, value: Any) -> Any:
    """The value as spec.kind; an int is accepted for a double (YAML writes 20, not 20.0)."""
    if spec.kind is float and isinstance(value, int) and not isinstance(value, bool):
        return float(value)
    if not isinstance(value, spec.kind):
        raise ParameterError(
            f"parameter {spec.name!r} is {value!r} ({type(value).__name__}); "
            f"expected a {spec.kind.__name__}"
        )
    return value


def declare(node: Node, specs: Sequence[ParamSpec]) -> dict[str, Any]:
    """Declare ``specs`` on the node (so parameter files naming them load) and read them back."""
    from rcl_interfaces.msg import ParameterDescriptor

    values: dict[str, Any] = {}
    for spec in specs:
        # Dynamic typing so an integer override of a double does not abort the declaration;
        # coerce() then checks the type with a readable message.
        if node.has_parameter(spec.name):  # declared already from the overrides
            value = node.get_parameter(spec.name).value
        else:
            descriptor = ParameterDescriptor(dynamic_typing=True)
            value = node.declare_parameter(spec.name, spec.default, descriptor).value
        values[spec.name] = coerce(spec, spec.default if value is None else value)
    return values


@dataclass
class StatePublisher:
    """The node's behaviour: latch the URDF, validate replacements, keep joint positions."""

    node: Node
    publisher: Publisher
    robot: Robot
    urdf: str
    positions: dict[str, float] = field(default_factory=dict)
    unknown_joints: set[str] = field(default_factory=set)

    def publish_description(self) -> None:
        """Send the URDF on robot_description (latched: late subscribers get it too)."""
        from std_msgs.msg import String

        self.publisher.publish(String(data=self.urdf))

    def log_segments(self) -> None:
        """Log each link as the real node does, so a reader of the log sees the tree was read."""
        for link in self.robot.links:
            self.node.get_logger().info(f"got segment {link}")

    def on_joint_states(self, msg: JointState) -> None:
        """Keep the latest position of every known joint; name unknown joints once each."""
        for index, name in enumerate(msg.name):
            if name not in self.robot.joints:
                if name not in self.unknown_joints:
                    self.unknown_joints.add(name)
                    self.node.get_logger().warn(
                        f"joint_states names joint {name!r}, which is not in robot "
                        f"{self.robot.name!r}; ignoring it"
                    )
                continue
            if index < len(msg.position):
                self.positions[name] = msg.position[index]

    def on_set_parameters(self, params: list[Parameter]) -> Any:
        """Accept a new robot_description only if it parses; then publish it at once."""
        from rcl_interfaces.msg import SetParametersResult

        for param in params:
            if param.name != "robot_description":
                continue
            try:
                text = coerce(PARAMS[0], param.value)
                robot = parse_urdf(text)
            except (UrdfError, ParameterError) as exc:
                return SetParametersResult(successful=False, reason=str(exc))
            self.robot, self.urdf = robot, text
            self.positions.clear()
            self.unknown_joints.clear()
            self.publish_description()
            self.log_segments()
        return SetParametersResult(successful=True)


def start(node: Node) -> StatePublisher:
    """Read the parameters, check the URDF, wire publisher and subscription; raise on bad input."""
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy, qos_profile_sensor_data
    from sensor_msgs.msg import JointState
    from std_msgs.msg import String

    values = declare(node, PARAMS)
    text = values["robot_description"]
    if not text.strip():
        raise ParameterError(
            "parameter 'robot_description' is empty or not set; "
            "pass the URDF text (e.g. parameters=[{'robot_description': urdf}])"
        )
    robot = parse_urdf(text)
    latched = QoSProfile(
        depth=1,
        reliability=ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.TRANSIENT_LOCAL,
    )
    publisher = node.create_publisher(String, "robot_description", latched)
    state = StatePublisher(node, publisher, robot, text)
    # The real node reads joint_states with sensor-data QoS; best effort also hears reliable ones.
    node.create_subscription(
        JointState, "joint_states", state.on_joint_states, qos_profile_sensor_data
    )
    node.add_on_set_parameters_callback(state.on_set_parameters)
    state.log_segments()
    state.publish_description()
    node.get_logger().info(
        "stand-in: /tf and /tf_static are not published (no tf2_msgs package in this environment)"
    )
    return state


def main(argv: Sequence[str] | None = None) -> int:
    """Run the node until shutdown; 1 with a one-line error when its input is unusable."""
    from rclpy.node import Node

    args = [sys.argv[0], *(sys.argv[1:] if argv is None else argv)]
    stop = init_ros(args, NODE_NAME)
    if stop is None:
        return EXIT_FAILURE
    node = Node(NODE_NAME)
    return spin_until_shutdown(node, lambda: start(node), INPUT_ERRORS, stop)


if __name__ == "__main__":
    sys.exit(main())
