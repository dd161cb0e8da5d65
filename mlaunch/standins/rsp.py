"""Stand-in for robot_state_publisher: ``python -m mlaunch.standins.rsp [--ros-args ...]``.

It takes the real node's parameters, refuses an invalid URDF the way the real one does (but with a
one-line message and exit status 1), latches the URDF on ``robot_description`` for late
subscribers (the simulator, joint_state_publisher and the viewer read it there), publishes the
fixed joints on /tf_static at start and the moving joints on /tf from ``joint_states`` (forward
kinematics, at most ``publish_frequency`` per joint, stamped with the joint state's stamp,
``frame_prefix`` on every frame), as the real node does. Without tf2_msgs (see interfaces/) it
says once that /tf is not published. Mimic joints are not followed.
rclpy is imported inside main() only, so importing this module stays cheap.
"""

from __future__ import annotations

import sys
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from mlaunch.plan.errors import StandinError
from mlaunch.standins import transforms
from mlaunch.standins.common import EXIT_FAILURE, init_ros, spin_until_shutdown
from mlaunch.standins.urdf import Robot, UrdfError, joint_transform, parse_urdf

if TYPE_CHECKING:
    from rclpy.node import Node
    from rclpy.parameter import Parameter
    from rclpy.publisher import Publisher
    from sensor_msgs.msg import JointState

NODE_NAME = "robot_state_publisher"


class ParameterError(StandinError, ValueError):
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
        value = float(value)
    if not isinstance(value, spec.kind):
        raise ParameterError(
            f"parameter {spec.name!r} is {value!r} ({type(value).__name__}); "
            f"expected a {spec.kind.__name__}"
        )
    if spec.name == "publish_frequency" and not 0.0 < value <= 1000.0:  # type: ignore[operator]
        raise ParameterError(
            f"parameter 'publish_frequency' is {value!r}; it must be above 0 and at most 1000"
        )
    return value


# Joint types whose transform never changes (KDL turns a planar joint into a fixed one) and those
# robot_state_publisher skips altogether.
STATIC_JOINTS = ("fixed", "planar")
SKIPPED_JOINTS = ("floating",)


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
    options: dict[str, Any]
    tf: Any = None  # transforms.Broadcaster, or None without tf2_msgs
    tf_static: Any = None
    positions: dict[str, float] = field(default_factory=dict)
    unknown_joints: set[str] = field(default_factory=set)
    # joint -> stamp (ns) of the joint state it was last published for
    last_published: dict[str, int] = field(default_factory=dict)
    last_callback_ns: int = 0

    def publish_description(self) -> None:
        """Send the URDF on robot_description (latched: late subscribers get it too)."""
        from std_msgs.msg import String

        self.publisher.publish(String(data=self.urdf))

    def log_segments(self) -> None:
        """Log each link as the real node does, so a reader of the log sees the tree was read."""
        for link in self.robot.links:
            self.node.get_logger().info(f"got segment {link}")

    def publish_fixed_transforms(self) -> None:
        """The fixed joints on /tf_static, stamped now (the static broadcaster latches them)."""
        if self.tf_static is None:
            return
        stamp = self.node.get_clock().now().to_msg()
        prefix = self.options["frame_prefix"]
        self.tf_static.send(
            transforms.from_matrix(
                prefix + joint.parent, prefix + joint.child, joint_transform(joint, 0.0), stamp
            )
            for joint in self.robot.joints.values()
            if joint.type in STATIC_JOINTS
        )

    def publish_moving_transforms(self, positions: dict[str, float], stamp: Any) -> None:
        """The moving joints named in one joint state, on /tf with that state's stamp."""
        if self.tf is None:
            return
        prefix = self.options["frame_prefix"]
        self.tf.send(
            transforms.from_matrix(
                prefix + j.parent, prefix + j.child, joint_transform(j, q), stamp
            )
            for name, q in positions.items()
            if (j := self.robot.joints.get(name)) is not None
            and j.type not in STATIC_JOINTS + SKIPPED_JOINTS
        )

    def due(self, msg: JointState) -> bool:
        """Whether a joint state is due for /tf: publish_frequency limits each joint's rate.

        As the real node: a state is published when its stamp is at least one period (whole
        milliseconds) after the least recently published of its joints, or always with
        ignore_timestamp; going back in time (a bag or simulator restart) starts over.
        """
        now = self.node.get_clock().now().nanoseconds
        if self.last_callback_ns > now:
            self.node.get_logger().warn("Moved backwards in time, re-publishing joint transforms!")
            self.last_published.clear()
        self.last_callback_ns = now
        oldest = min((self.last_published.get(name, 0) for name in msg.name), default=now)
        oldest = min(oldest, now)
        interval_ns = int(1000.0 / self.options["publish_frequency"]) * 1_000_000
        stamp_ns = msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec
        return bool(self.options["ignore_timestamp"]) or stamp_ns >= oldest + interval_ns

    def on_joint_states(self, msg: JointState) -> None:
        """Keep the latest joint positions, publish the moving joints on /tf when due."""
        if len(msg.name) != len(msg.position):
            if not msg.position and msg.name:
                self.node.get_logger().warn(
                    "Robot state publisher ignored a JointState message about joint(s) "
                    f'"{msg.name[0]}"(,...) whose position member was empty.'
                )
            else:
                self.node.get_logger().error(
                    "Robot state publisher ignored an invalid JointState message"
                )
            return
        self.remember(msg)
        if self.due(msg):
            self.publish_moving_transforms(
                dict(zip(msg.name, msg.position, strict=True)), msg.header.stamp
            )
            stamp_ns = msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec
            for name in msg.name:
                self.last_published[name] = stamp_ns

    def remember(self, msg: JointState) -> None:
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

        specs = {spec.name: spec for spec in PARAMS}
        for param in params:
            if param.name not in specs:
                continue
            try:
                value = coerce(specs[param.name], param.value)
                robot = parse_urdf(value) if param.name == "robot_description" else None
            except (UrdfError, ParameterError) as exc:
                return SetParametersResult(successful=False, reason=str(exc))
            if robot is None:
                self.options[param.name] = value
                continue
            self.robot, self.urdf = robot, value
            self.positions.clear()
            self.unknown_joints.clear()
            self.last_published.clear()
            self.publish_description()
            self.log_segments()
            self.publish_fixed_transforms()
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
    state = StatePublisher(node, publisher, robot, text, values)
    if transforms.have_tf2_msgs():
        state.tf = transforms.Broadcaster(node)
        state.tf_static = transforms.StaticBroadcaster(node)
    else:
        node.get_logger().info(f"stand-in: {transforms.MISSING_NOTE}")
    # The real node reads joint_states with sensor-data QoS; best effort also hears reliable ones.
    node.create_subscription(
        JointState, "joint_states", state.on_joint_states, qos_profile_sensor_data
    )
    node.add_on_set_parameters_callback(state.on_set_parameters)
    state.log_segments()
    state.publish_description()
    state.publish_fixed_transforms()
    node.get_logger().info("Robot initialized")
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
