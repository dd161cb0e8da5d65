"""Stand-in for rviz2: ``python -m mlaunch.standins.viewer [-d CONFIG] [-f FRAME] [ROS args]``.

There is no RViz here, so this node serves a small web page on 127.0.0.1 that draws, top-down,
the simulator's world (its walls and obstacles, world_topic.py), the robot outline from
``robot_description`` at its odometry pose, the odometry trail and the laser scan (placed
through /tf and /tf_static when they are published), and shows the depth image of an Image
display. It takes rviz2's command line and reads the fixed frame and the topics from a
display config (viewer_config.py). Only the standard library serves the page (http.server
in a thread); rclpy is imported inside main() only.
"""

from __future__ import annotations

import math
import os
import sys
import threading
import time
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

from mlaunch.standins.common import init_ros, latched, spin
from mlaunch.standins.urdf import Circle, Robot, UrdfError, parse_urdf
from mlaunch.standins.viewer_config import (
    DisplayConfig,
    ViewerError,
    parse_args,
    read_display_config,
    viewer_port,
)
from mlaunch.standins.viewer_config import config_from_data as config_from_data
from mlaunch.standins.viewer_http import PageServer as PageServer
from mlaunch.standins.viewer_http import serve, twist_driver
from mlaunch.standins.viewer_tf import DepthPicture, PlanarTf, compose, invert, planar, yaw_of
from mlaunch.standins.world_topic import WORLD_TOPIC, WorldPicture

if TYPE_CHECKING:
    from nav_msgs.msg import Odometry
    from rclpy.node import Node
    from sensor_msgs.msg import LaserScan
    from std_msgs.msg import String

NODE_NAME = "rviz"
EXIT_OK = 0
EXIT_FAILURE = 1
TRAIL_MAX = 5000
TRAIL_STEP = 0.02  # metres between trail points: enough for a smooth line, bounded memory
PAGE_IDLE_S = 5.0  # a page that has not polled for this long is closed (the depth feed stops)
LOST_S = 3.0  # odometry silent this long: the robot drawn is where it was, not where it is

Pose2D = tuple[float, float, float]  # x, y, yaw
# compose, invert, yaw_of and config_from_data are re-exported: tests know them from here.
__all__ = ["compose", "config_from_data", "invert", "yaw_of"]


# ---------------------------------------------------------------- what the page shows


@dataclass
class TopicStats:
    """How many messages a topic brought and when the last one came (monotonic seconds)."""

    topic: str
    count: int = 0
    last: float | None = None

    def to_json(self, now: float) -> dict[str, Any]:
        age = None if self.last is None else round(now - self.last, 3)
        return {"topic": self.topic, "count": self.count, "age": age}


@dataclass
class ViewerState:
    """Everything the page draws, in the odometry frame; updated from ROS callbacks, read by HTTP.

    Kept free of rclpy so it can be tested with plain numbers. All access goes through the lock,
    because callbacks run in the spinning thread and requests in the server's threads.
    """

    config: DisplayConfig
    robot: Robot | None = None
    robot_error: str | None = None
    pose: Pose2D | None = None
    odom_frame: str = ""
    base_frame: str = ""
    trail: deque[tuple[float, float]] = field(default_factory=lambda: deque(maxlen=TRAIL_MAX))
    scan_points: list[tuple[float, float]] = field(default_factory=list)
    scan_frame: str = ""
    seq: int = 0
    warnings: dict[str, str] = field(default_factory=dict)
    stats: dict[str, TopicStats] = field(default_factory=dict)
    tf: PlanarTf = field(default_factory=PlanarTf)
    last_poll: float = -math.inf
    depth: DepthPicture = field(default_factory=DepthPicture)
    world: WorldPicture = field(default_factory=WorldPicture)
    restarted_at: float | None = None  # when the simulator last came back (a new world run)
    restarts: int = 0
    had_robot: bool = False  # the restarted simulator's predecessor had this robot
    lock: threading.Lock = field(default_factory=threading.Lock, repr=False)

    def __post_init__(self) -> None:
        for key, topic in (
            ("description", self.config.description_topic),
            ("odom", self.config.odom_topic),
            ("scan", self.config.scan_topic),
            ("tf", "/tf"),
            ("world", WORLD_TOPIC),
            *((("depth", self.config.depth_topic),) if self.config.depth_topic else ()),
        ):
            self.stats[key] = TopicStats(topic)

    def _seen(self, key: str, now: float) -> None:
        stats = self.stats[key]
        stats.count += 1
        stats.last = now
        self.seq += 1

    def set_description(self, text: str, now: float) -> None:
        """A URDF from the description topic; an invalid one is shown on the page, not drawn."""
        try:
            robot, error = parse_urdf(text), None
        except UrdfError as exc:
            robot, error = None, str(exc)
        with self.lock:
            self.robot, self.robot_error = robot, error
            self._seen("description", now)

    def set_world(self, text: str, now: float) -> None:
        """The simulator's world (world_topic.py); a malformed one is shown on the page."""
        with self.lock:
            if self.world.set(text):  # a new simulator: the robot drawn so far is gone
                self.pose, self.scan_points, self.restarted_at = None, [], now
                self.had_robot = self.stats["odom"].last is not None
                self.trail.clear()
                self.restarts += 1
            self._seen("world", now)

    def set_odom(self, frame: str, child: str, pose: Pose2D, now: float) -> None:
        """The robot's pose in the odometry frame; extends the trail when it moved."""
        with self.lock:
            self.pose, self.odom_frame, self.base_frame = pose, frame, child
            x, y = pose[0], pose[1]
            if not self.trail or math.dist(self.trail[-1], (x, y)) >= TRAIL_STEP:
                self.trail.append((round(x, 4), round(y, 4)))
            self._seen("odom", now)

    def set_transforms(self, transforms: Sequence[tuple[str, str, Pose2D]], now: float) -> None:
        """Transforms (parent, child, pose seen from above) from /tf or /tf_static."""
        with self.lock:
            for parent, child, pose in transforms:
                self.tf.set(parent, child, pose)
            self._seen("tf", now)

    def set_depth(
        self, width: int, height: int, encoding: str, data: Any, far: float, now: float
    ) -> None:
        """A depth image for the page's picture."""
        with self.lock:
            self.depth.set(width, height, encoding, data, far)
            self._seen("depth", now)

    def depth_png(self) -> bytes | None:
        with self.lock:
            return self.depth.png()

    def note_poll(self, now: float) -> None:
        """A page asked for the state: it is open."""
        with self.lock:
            self.last_poll = now

    def page_open(self, now: float) -> bool:
        """Whether a page polled in the last PAGE_IDLE_S seconds."""
        with self.lock:
            return now - self.last_poll < PAGE_IDLE_S

    def _in_odom(self, frame: str) -> Pose2D | None:
        """Where a frame is in the odometry (or fixed) frame by TF, when TF connects them."""
        reference = self.odom_frame or self.config.fixed_frame
        return self.tf.lookup(reference, frame) if frame else None

    def set_scan(
        self,
        frame: str,
        angle_min: float,
        angle_increment: float,
        ranges: Sequence[float],
        range_limits: tuple[float, float],
        now: float,
    ) -> None:
        """A laser scan, turned into points in the odometry frame at the robot's current pose."""
        low, high = range_limits
        with self.lock:
            # TF places the laser where it is (any mount, any tree); without TF, the odometry
            # pose and the URDF at zero joints do.
            laser = self._in_odom(frame) or compose(
                self.pose or (0.0, 0.0, 0.0), self._laser_in_base(frame)
            )
            points = []
            for index, r in enumerate(ranges):
                if not math.isfinite(r) or r < low or r > high:
                    continue  # no return: rviz draws nothing there either
                angle = angle_min + index * angle_increment
                px, py, _ = compose(laser, (r * math.cos(angle), r * math.sin(angle), 0.0))
                points.append((round(px, 4), round(py, 4)))
            self.scan_points, self.scan_frame = points, frame
            self._seen("scan", now)

    def _link(self, frame: str) -> str | None:
        """The URDF link a tf frame names, allowing for a frame_prefix such as ``r1/``."""
        if self.robot is None or not frame:
            return None
        for name in (frame, frame.rsplit("/", 1)[-1]):
            if name in self.robot.links:
                return name
        return None

    def _in_base(self, link: str) -> Pose2D:
        """Pose of a URDF link in the odometry child (base) frame, joints at zero."""
        assert self.robot is not None
        x, y, _, yaw = self.robot.link_pose_in_root(link)
        base = self._link(self.base_frame) or self.robot.root
        bx, by, _, byaw = self.robot.link_pose_in_root(base)
        return compose(invert((bx, by, byaw)), (x, y, yaw))

    def _laser_in_base(self, frame: str) -> Pose2D:
        link = self._link(frame)
        if link is None:
            if self.robot is not None:
                self.warnings["laser"] = (
                    f"laser frame {frame!r} is not a link of {self.robot.name!r}: "
                    "scan drawn at the robot's base"
                )
            return (0.0, 0.0, 0.0)
        self.warnings.pop("laser", None)
        return self._in_base(link)

    def _shapes(self) -> list[dict[str, Any]]:
        """The robot outline in the base frame (the URDF gives it in the root frame)."""
        if self.robot is None:
            return []
        base = self._link(self.base_frame) or self.robot.root
        bx, by, _, byaw = self.robot.link_pose_in_root(base)
        to_base = invert((bx, by, byaw))
        shapes = []
        for shape in self.robot.footprint():
            data = shape.to_json()
            if isinstance(shape, Circle):
                data["x"], data["y"] = _moved(to_base, (shape.x, shape.y))
            else:
                data["points"] = [_moved(to_base, p) for p in shape.points]
            shapes.append(data)
        return shapes

    def snapshot(self, now: float) -> dict[str, Any]:
        """The page's JSON: a consistent copy taken under the lock."""
        with self.lock:
            fixed = self.config.fixed_frame
            robot = None
            if self.robot is not None:
                robot = {"name": self.robot.name, "root": self.robot.root, "shapes": self._shapes()}
            current = self.pose
            gone = self._gone()
            if current is None and self.robot is not None and not gone:  # TF may place it
                current = self._in_odom(self.base_frame or self.robot.root)
            pose = None if current is None else dict(zip(("x", "y", "yaw"), current, strict=True))
            return {
                "seq": self.seq,
                "fixed_frame": fixed,
                # A fixed frame on the robot (base_link) means the world moves around the robot.
                "robot_centric": self._link(fixed) is not None,
                "odom_frame": self.odom_frame,
                "base_frame": self.base_frame,
                "robot": None if gone else robot,
                "robot_error": self.robot_error,
                "simulator": {"restarts": self.restarts, "robot": self._robot_status(now)},
                "pose": pose,
                "trail": [list(p) for p in self.trail],
                "scan": {"frame": self.scan_frame, "points": [list(p) for p in self.scan_points]},
                "topics": {key: stats.to_json(now) for key, stats in self.stats.items()},
                "depth": None
                if self.depth.grey is None
                else {
                    "seq": self.depth.seq,
                    "topic": self.config.depth_topic,
                    "size": list(self.depth.size),
                    "encoding": self.depth.encoding,
                },
                "frames": self.tf.frames(),
                # The walls under the robot, in the frame everything else here is in.
                "world": self.world.in_frame(self.odom_frame or fixed),
                "warnings": [
                    *self._status_lines(now),
                    *self.config.warnings,
                    *self.warnings.values(),
                    *((self.world.error,) if self.world.error else ()),
                ],
            }

    def _gone(self) -> bool:
        """The simulator restarted and this robot has not been seen in the new one."""
        odom = self.stats["odom"].last
        restarted = self.restarted_at is not None and self.had_robot
        return restarted and (odom is None or odom < (self.restarted_at or 0.0))

    def _robot_status(self, now: float) -> str:
        """'gone' (not in the restarted simulator), 'lost' (odometry silent), 'live', 'waiting'."""
        last = self.stats["odom"].last
        if self._gone():
            return "gone"
        if last is None:
            return "waiting"
        return "lost" if now - last > LOST_S else "live"

    def _status_lines(self, now: float) -> list[str]:
        status, odom = self._robot_status(now), self.config.odom_topic
        if status == "gone":
            return [
                f"the simulator restarted and the robot is not in it (nothing on {odom} since):"
                " spawn it again"
            ]
        if status == "lost":
            silent = now - (self.stats["odom"].last or now)
            return [f"no odometry on {odom} for {silent:.0f} s: the robot is drawn where it was"]
        if self.restarted_at is not None and now - self.restarted_at < 10:
            return ["the simulator restarted: showing the new state"]
        return []


def _moved(transform: Pose2D, point: tuple[float, float]) -> list[float]:
    x, y, _ = compose(transform, (point[0], point[1], 0.0))
    return [round(x, 5), round(y, 5)]


# ---------------------------------------------------------------- ROS


def subscribe(node: Node, state: ViewerState) -> None:
    """Subscribe to the robot description, odometry and scan with the QoS their publishers use."""
    from nav_msgs.msg import Odometry
    from rclpy.qos import qos_profile_sensor_data
    from sensor_msgs.msg import LaserScan
    from std_msgs.msg import String

    latest = latched()

    def on_description(msg: String) -> None:
        state.set_description(msg.data, time.monotonic())

    def on_odom(msg: Odometry) -> None:
        p, q = msg.pose.pose.position, msg.pose.pose.orientation
        pose = (p.x, p.y, yaw_of(q.x, q.y, q.z, q.w))
        state.set_odom(msg.header.frame_id, msg.child_frame_id, pose, time.monotonic())

    def on_scan(msg: LaserScan) -> None:
        limits = (msg.range_min, msg.range_max)
        state.set_scan(
            msg.header.frame_id,
            msg.angle_min,
            msg.angle_increment,
            msg.ranges,
            limits,
            time.monotonic(),
        )

    def on_world(msg: String) -> None:
        state.set_world(msg.data, time.monotonic())

    config = state.config
    node.create_subscription(String, config.description_topic, on_description, latest)
    node.create_subscription(String, WORLD_TOPIC, on_world, latest)
    # Best effort hears both best-effort (simulated sensors) and reliable publishers.
    node.create_subscription(Odometry, config.odom_topic, on_odom, qos_profile_sensor_data)
    node.create_subscription(LaserScan, config.scan_topic, on_scan, qos_profile_sensor_data)
    # /tf_static has one latched message per broadcaster: depth 100, as tf2's static listener,
    # so one that arrives while another waits to be taken does not replace it.
    subscribe_tf_and_depth(node, state, latched(100), qos_profile_sensor_data)


def subscribe_tf_and_depth(node: Node, state: ViewerState, latched: Any, sensor: Any) -> None:
    """/tf and /tf_static where tf2_msgs is installed; the depth image when the config has one."""
    from mlaunch.standins.transforms import have_tf2_msgs

    if have_tf2_msgs():
        from tf2_msgs.msg import TFMessage

        def on_tf(msg: TFMessage) -> None:
            state.set_transforms(
                [
                    (
                        t.header.frame_id,
                        t.child_frame_id,
                        planar(t.transform.translation, t.transform.rotation),
                    )
                    for t in msg.transforms
                ],
                time.monotonic(),
            )

        node.create_subscription(TFMessage, "/tf", on_tf, 100)
        node.create_subscription(TFMessage, "/tf_static", on_tf, latched)
    if state.config.depth_topic:
        from rclpy.clock import Clock
        from rclpy.clock_type import ClockType

        feed = DepthFeed(node, state)
        # Steady time: under use_sim_time a paused /clock must not keep a closed page's feed.
        node.create_timer(0.5, feed.tick, clock=Clock(clock_type=ClockType.STEADY_TIME))


class DepthFeed:
    """The depth image subscription, held only while a page polls.

    Each image costs the simulator a ray cast and this process a megabyte copy: with no page
    open nobody would see them, so the subscription (and the camera's rendering, which only runs
    for subscribers) stops until a page polls again.
    """

    def __init__(self, node: Node, state: ViewerState) -> None:
        from rclpy.qos import QoSProfile, ReliabilityPolicy

        self.node, self.state = node, state
        # Depth 1: only the newest picture matters, an old one is never worth the copy.
        self.qos = QoSProfile(depth=1, reliability=ReliabilityPolicy.BEST_EFFORT)
        self.subscription: Any = None

    def tick(self) -> None:
        from sensor_msgs.msg import Image

        wanted = self.state.page_open(time.monotonic())
        if wanted and self.subscription is None:
            topic = self.state.config.depth_topic
            self.subscription = self.node.create_subscription(Image, topic, self.on_depth, self.qos)
        elif not wanted and self.subscription is not None:
            self.node.destroy_subscription(self.subscription)
            self.subscription = None

    def on_depth(self, msg: Any) -> None:
        self.state.set_depth(msg.width, msg.height, msg.encoding, msg.data, 0.0, time.monotonic())


def main(argv: Sequence[str] | None = None) -> int:
    """Run the viewer until shutdown; 1 with a one-line error when its input is unusable."""
    args = [sys.argv[0], *(sys.argv[1:] if argv is None else argv)]
    from rclpy.executors import ExternalShutdownException
    from rclpy.node import Node
    from rclpy.utilities import remove_ros_args, try_shutdown

    try:
        options = parse_args(remove_ros_args(args)[1:])
        port = viewer_port(dict(os.environ))
    except ViewerError as exc:
        print(f"[ERROR] [{NODE_NAME}]: {exc}", file=sys.stderr)
        return EXIT_FAILURE
    config = read_display_config(options.display_config)
    if options.fixed_frame:
        config = replace(config, fixed_frame=options.fixed_frame)
    stop = init_ros(args, NODE_NAME)
    if stop is None:
        return EXIT_FAILURE
    node = Node(NODE_NAME)
    server = None
    try:
        for warning in config.warnings:
            node.get_logger().warn(warning)
        state = ViewerState(config)
        subscribe(node, state)
        server = serve(state, port, time.monotonic, twist_driver(node))
        node.get_logger().info(
            f"stand-in for rviz2: fixed frame {config.fixed_frame!r}, drawing "
            f"{config.description_topic}, {config.odom_topic}, {config.scan_topic}; the page's"
            " arrow keys publish cmd_vel"
        )
        print(f"viewer: open http://127.0.0.1:{server.server_address[1]}/", flush=True)
        spin(node, stop)
    except ViewerError as exc:
        node.get_logger().error(str(exc))
        return EXIT_FAILURE
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if server is not None:
            server.shutdown()
            server.server_close()
        node.destroy_node()
        try_shutdown()
    return EXIT_OK


if __name__ == "__main__":
    sys.exit(main())
