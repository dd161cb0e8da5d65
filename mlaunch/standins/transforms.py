"""TF for the stand-ins: transforms as messages, and the /tf and /tf_static broadcasters.

robot_state_publisher, static_transform_publisher and the simulator publish transforms the way
tf2_ros's broadcasters do: /tf reliable and volatile (depth 100), /tf_static reliable and
transient local (depth 1) carrying every static transform this node ever sent, so a late
listener gets them all in one message. ``tf2_msgs`` has no wheel on PyPI: scripts/setup builds it
(interfaces/); where it is missing, ``have_tf2_msgs()`` is False and callers say so once.
The math is pure Python; rclpy and the message types are imported inside the functions only.
"""

from __future__ import annotations

import importlib.util
import math
from collections.abc import Iterable, Sequence
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from geometry_msgs.msg import TransformStamped
    from rclpy.node import Node

Quaternion = tuple[float, float, float, float]  # x, y, z, w
Vec3 = tuple[float, float, float]
MISSING_NOTE = "/tf is not published: tf2_msgs is not installed (./scripts/setup builds it)"


def have_tf2_msgs() -> bool:
    """Whether the TFMessage type can be imported here (a ROS installation or our wheel)."""
    return importlib.util.find_spec("tf2_msgs") is not None


def quaternion_from_rpy(roll: float, pitch: float, yaw: float) -> Quaternion:
    """Fixed-axis roll, pitch, yaw (R = Rz(yaw) Ry(pitch) Rx(roll)), as tf2 and URDF use them."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
        cr * cp * cy + sr * sp * sy,
    )


def quaternion_from_matrix(m: Sequence[Sequence[float]]) -> Quaternion:
    """The unit quaternion of the rotation part of a 3x3 or 4x4 matrix.

    Computed as KDL's Rotation::GetQuaternion does, sign included (w may be negative), because
    the real robot_state_publisher publishes what KDL gives: the same rotation with the other
    sign would be a different /tf message (tests/test_real_nodes.py compares them).
    """
    trace = m[0][0] + m[1][1] + m[2][2]
    if trace > 1e-12:  # KDL's epsilon
        s = 2.0 * math.sqrt(trace + 1.0)
        q = ((m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s, s / 4)
    elif m[0][0] > m[1][1] and m[0][0] > m[2][2]:
        s = 2.0 * math.sqrt(1.0 + m[0][0] - m[1][1] - m[2][2])
        q = (s / 4, (m[0][1] + m[1][0]) / s, (m[0][2] + m[2][0]) / s, (m[2][1] - m[1][2]) / s)
    elif m[1][1] > m[2][2]:
        s = 2.0 * math.sqrt(1.0 + m[1][1] - m[0][0] - m[2][2])
        q = ((m[0][1] + m[1][0]) / s, s / 4, (m[1][2] + m[2][1]) / s, (m[0][2] - m[2][0]) / s)
    else:
        s = 2.0 * math.sqrt(1.0 + m[2][2] - m[0][0] - m[1][1])
        q = ((m[0][2] + m[2][0]) / s, (m[1][2] + m[2][1]) / s, s / 4, (m[1][0] - m[0][1]) / s)
    return q


def transform(
    parent: str, child: str, xyz: Vec3, rotation: Quaternion, stamp: Any
) -> TransformStamped:
    """A geometry_msgs/TransformStamped of ``child`` in ``parent`` at ``stamp`` (a Time msg)."""
    from geometry_msgs.msg import TransformStamped

    msg = TransformStamped()
    msg.header.stamp = stamp
    msg.header.frame_id = parent
    msg.child_frame_id = child
    t, r = msg.transform.translation, msg.transform.rotation
    t.x, t.y, t.z = (float(v) for v in xyz)
    r.x, r.y, r.z, r.w = (float(v) for v in rotation)
    return msg


def from_matrix(parent: str, child: str, m: Sequence[Sequence[float]], stamp: Any) -> Any:
    """The TransformStamped of a 4x4 homogeneous matrix."""
    return transform(parent, child, (m[0][3], m[1][3], m[2][3]), quaternion_from_matrix(m), stamp)


def _tf_publisher(node: Node, topic: str, depth: int, latched: bool) -> tuple[Any, Any]:
    """(TFMessage, a reliable publisher on topic): transient local when latched."""
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
    from tf2_msgs.msg import TFMessage

    durability = DurabilityPolicy.TRANSIENT_LOCAL if latched else DurabilityPolicy.VOLATILE
    qos = QoSProfile(depth=depth, reliability=ReliabilityPolicy.RELIABLE, durability=durability)
    return TFMessage, node.create_publisher(TFMessage, topic, qos)


class Broadcaster:
    """Publishes on /tf as tf2_ros.TransformBroadcaster: reliable, volatile, depth 100."""

    def __init__(self, node: Node) -> None:
        self._message, self._publisher = _tf_publisher(node, "/tf", 100, latched=False)

    def send(self, transforms: Iterable[Any]) -> None:
        self._publisher.publish(self._message(transforms=list(transforms)))


class StaticBroadcaster:
    """Publishes on /tf_static as tf2_ros.StaticTransformBroadcaster.

    Latched (transient local, depth 1), and every message carries all the transforms sent so
    far, the newest one per child frame, because a late subscriber only gets the last message.
    """

    def __init__(self, node: Node) -> None:
        self._message, self._publisher = _tf_publisher(node, "/tf_static", 1, latched=True)
        self._by_child: dict[str, Any] = {}

    def send(self, transforms: Iterable[Any]) -> None:
        for item in transforms:
            self._by_child[item.child_frame_id] = item
        self._publisher.publish(self._message(transforms=list(self._by_child.values())))
