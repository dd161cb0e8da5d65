"""Stand-in for joint_state_publisher: ``python -m mlaunch.standins.jsp [urdf_file] [ROS args]``.

Publishes ``joint_states`` for every non-fixed joint of the robot at its default position, at
``rate`` Hz. The URDF comes from the optional file argument, else the ``robot_description``
parameter, else the latched ``robot_description`` topic, in the same order as the real ROS 2 node.
Stamps come from the node clock, so with use_sim_time it waits for /clock instead of stamping 0.
rclpy is imported inside main() only.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from mlaunch.standins.common import EXIT_FAILURE, init_ros, spin_until_shutdown
from mlaunch.standins.rsp import INPUT_ERRORS, ParameterError, ParamSpec, declare
from mlaunch.standins.urdf import Joint, Robot, UrdfError, parse_urdf

if TYPE_CHECKING:
    from rclpy.node import Node
    from rclpy.publisher import Publisher
    from std_msgs.msg import String

NODE_NAME = "joint_state_publisher"

PARAMS = (
    ParamSpec("robot_description", "", str),
    ParamSpec("rate", 10.0, float),
    ParamSpec("publish_default_positions", True, bool),
    ParamSpec("publish_default_velocities", False, bool),
    ParamSpec("publish_default_efforts", False, bool),
    ParamSpec("use_mimic_tags", True, bool),
    ParamSpec("use_smallest_joint_limits", True, bool),
    ParamSpec("delta", 0.0, float),
)


def default_position(joint: Joint, zeros: Mapping[str, float]) -> float:
    """Where a joint starts: ``zeros`` if given, else 0 if within its limits, else mid-range.

    The real node does the same, so a revolute joint limited to [0.5, 1.5] starts at 1.0.
    """
    if joint.name in zeros:
        return zeros[joint.name]
    if joint.lower is not None and joint.upper is not None and not joint.lower <= 0 <= joint.upper:
        return (joint.lower + joint.upper) / 2
    return 0.0


def read_zeros(node: Node) -> dict[str, float]:
    """The ``zeros.<joint>`` parameters (a ``zeros:`` mapping in a parameter file)."""
    zeros: dict[str, float] = {}
    for name in node.get_parameters_by_prefix("zeros"):
        value = node.get_parameter(f"zeros.{name}").value
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise ParameterError(f"parameter 'zeros.{name}' is {value!r}; expected a number")
        zeros[name] = float(value)
    return zeros


@dataclass
class JointPublisher:
    """The node's behaviour: hold the robot and publish its default joint states on a timer."""

    node: Node
    publisher: Publisher
    settings: dict[str, object]
    zeros: dict[str, float]
    robot: Robot | None = None
    waiting_logged: set[str] = field(default_factory=set)

    def use(self, robot: Robot) -> None:
        """Publish for ``robot`` from now on."""
        self.robot = robot
        names = ", ".join(j.name for j in robot.movable_joints()) or "none"
        self.node.get_logger().info(f"robot {robot.name!r}: publishing joints {names}")
        unknown = sorted(set(self.zeros) - {j.name for j in robot.movable_joints()})
        if unknown:
            self.node.get_logger().warn(f"zeros names joints not in the robot: {unknown}")

    def on_description(self, msg: String) -> None:
        """A URDF from the robot_description topic; a broken one is reported and skipped."""
        try:
            self.use(parse_urdf(msg.data))
        except UrdfError as exc:
            self.node.get_logger().error(f"robot_description topic: not a valid URDF: {exc}")

    def once(self, reason: str, text: str) -> None:
        """Log ``text`` the first time ``reason`` comes up (the timer would repeat it)."""
        if reason not in self.waiting_logged:
            self.waiting_logged.add(reason)
            self.node.get_logger().info(text)

    def tick(self) -> None:
        """Publish one joint_states message if there is a robot and a valid clock."""
        from sensor_msgs.msg import JointState

        if self.robot is None:
            self.once("urdf", "waiting for the URDF on the robot_description topic")
            return
        now = self.node.get_clock().now()
        if now.nanoseconds == 0:
            # use_sim_time and no /clock yet: a zero stamp would confuse every consumer.
            self.once("clock", "use_sim_time is true: waiting for /clock before publishing")
            return
        joints = self.robot.movable_joints()
        msg = JointState()
        msg.header.stamp = now.to_msg()
        msg.name = [j.name for j in joints]
        if self.settings["publish_default_positions"]:
            msg.position = [default_position(j, self.zeros) for j in joints]
        if self.settings["publish_default_velocities"]:
            msg.velocity = [0.0] * len(joints)
        if self.settings["publish_default_efforts"]:
            msg.effort = [0.0] * len(joints)
        self.publisher.publish(msg)


def parse_args(args: Sequence[str]) -> argparse.Namespace:
    """The node's own arguments (ROS arguments already removed): an optional URDF file."""
    parser = argparse.ArgumentParser(prog="joint_state_publisher")
    parser.add_argument("urdf_file", nargs="?", help="URDF file to use instead of the parameter")
    return parser.parse_args(list(args))


def start(node: Node, urdf_file: str | None) -> JointPublisher:
    """Read parameters, find the URDF (file, parameter or topic) and start the timer."""
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
    from sensor_msgs.msg import JointState
    from std_msgs.msg import String

    settings = declare(node, PARAMS)
    rate = settings["rate"]
    if not isinstance(rate, float) or rate <= 0:
        raise ParameterError(f"parameter 'rate' is {rate!r}; expected a positive number of Hz")
    publisher = node.create_publisher(JointState, "joint_states", 10)
    state = JointPublisher(node, publisher, settings, read_zeros(node))
    if urdf_file is not None:
        try:
            text = Path(urdf_file).read_text(encoding="utf-8")
        except OSError as exc:
            raise ParameterError(f"cannot read URDF file {urdf_file!r}: {exc.strerror}") from None
        state.use(parse_urdf(text))
    elif str(settings["robot_description"]).strip():
        state.use(parse_urdf(str(settings["robot_description"])))
    else:
        latched = QoSProfile(
            depth=1,
            reliability=ReliabilityPolicy.RELIABLE,
            durability=DurabilityPolicy.TRANSIENT_LOCAL,
        )
        node.create_subscription(String, "robot_description", state.on_description, latched)
    # The timer runs on the node clock: with use_sim_time it fires only as /clock advances.
    node.create_timer(1.0 / rate, state.tick)
    if node.get_clock().now().nanoseconds == 0:
        state.once("clock", "use_sim_time is true: waiting for /clock before publishing")
    return state


def main(argv: Sequence[str] | None = None) -> int:
    """Run the node until shutdown; 1 with a one-line error when its input is unusable."""
    from rclpy.node import Node
    from rclpy.utilities import remove_ros_args

    args = [sys.argv[0], *(sys.argv[1:] if argv is None else argv)]
    options = parse_args(remove_ros_args(args)[1:])
    stop = init_ros(args, NODE_NAME)
    if stop is None:
        return EXIT_FAILURE
    # zeros.<joint> are free-form names, so take whatever the overrides declare.
    node = Node(NODE_NAME, automatically_declare_parameters_from_overrides=True)
    return spin_until_shutdown(node, lambda: start(node, options.urdf_file), INPUT_ERRORS, stop)


if __name__ == "__main__":
    sys.exit(main())
