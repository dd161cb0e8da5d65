"""What a spawned robot asks of the simulator: its Gazebo plugins' parameters, and how it drives.

A URDF carries ``<gazebo>`` blocks naming Gazebo plugins (diff drive, ray sensor, IMU, ...) and
their settings. The simulator stand-in reads them here into plain dataclasses, resolves their ROS
topic names the way gazebo_ros does (plugin ``<ros><namespace>`` and ``<remapping>``), locates the
sensors on the robot through the URDF joint chain, and moves the robot with differential-drive
kinematics. Pure Python; never imports rclpy.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

from mlaunch.standins.camera import DEPTH_TYPES, CameraParams, parse_depth_camera
from mlaunch.standins.plugins import (
    CLASSIC_DIFF_DRIVE,
    CLASSIC_JOINT_STATES,
    DEFAULT_JOINT_STATE_RATE,
    GZ_DIFF_DRIVE,
    GZ_JOINT_STATES,
    IMU_TYPES,
    LIDAR_TYPES,
    ModelError,
    expand_topic,
    parse_ros_block,
    plugin_kind,
    positive,
    read_bool,
    read_float,
    read_int,
    read_text,
    where_of,
)
from mlaunch.standins.plugins import (
    RosNames as RosNames,  # re-exported: tests and callers know it from here
)
from mlaunch.standins.sensors import ImuParams, LidarParams, Mount, parse_imu, parse_lidar
from mlaunch.standins.urdf import Geometry, Robot
from mlaunch.standins.world import (
    Disc,
    Pose3,
    Shape,
    box_shape,
    cylinder_shape,
    sphere_shape,
)

# ---------------------------------------------------------------- diff drive


@dataclass(frozen=True)
class DiffDriveParams:
    """The diff-drive plugin's settings, with topics already resolved to absolute names."""

    plugin: str
    left_joints: tuple[str, ...]
    right_joints: tuple[str, ...]
    wheel_separation: float
    wheel_diameter: float
    max_wheel_acceleration: float = 0.0  # linear m/s^2 at the rim, as gazebo_ros applies it
    max_wheel_torque: float = 5.0
    update_rate: float = 100.0
    publish_odom: bool = False
    publish_odom_tf: bool = False
    publish_wheel_tf: bool = False
    odometry_frame: str = "odom"
    robot_base_frame: str = "base_footprint"
    odometry_source: int = 1  # 0 encoder (from the spawn pose), 1 world (Gazebo's ground truth)
    covariance: tuple[float, float, float] = (0.00001, 0.00001, 0.001)
    cmd_topic: str = "/cmd_vel"
    odom_topic: str = "/odom"
    namespace: str = "/"


def parse_classic_diff_drive(plugin: ET.Element, robot_namespace: str = "") -> DiffDriveParams:
    """libgazebo_ros_diff_drive.so: topics ``cmd_vel``/``odom`` in the plugin's namespace."""
    where = where_of(plugin)
    names = parse_ros_block(plugin, robot_namespace)
    left = tuple(_joint_names(plugin, "left_joint"))
    right = tuple(_joint_names(plugin, "right_joint"))
    _need_wheels(left, right, where)
    source = read_int(plugin, "odometry_source", 1, where)
    if source not in (0, 1):
        raise ModelError(
            f"{where}: <odometry_source> is {source}; expected 0 (encoder) or 1 (world)"
        )
    return DiffDriveParams(
        plugin=plugin.get("name", "diff_drive"),
        left_joints=left,
        right_joints=right,
        wheel_separation=positive(
            read_float(plugin, "wheel_separation", 0.34, where), "wheel_separation", where
        ),
        wheel_diameter=positive(
            read_float(plugin, "wheel_diameter", 0.15, where), "wheel_diameter", where
        ),
        max_wheel_acceleration=abs(read_float(plugin, "max_wheel_acceleration", 0.0, where)),
        max_wheel_torque=read_float(plugin, "max_wheel_torque", 5.0, where),
        update_rate=read_float(plugin, "update_rate", 100.0, where),
        publish_odom=read_bool(plugin, "publish_odom", False, where),
        publish_odom_tf=read_bool(plugin, "publish_odom_tf", False, where),
        publish_wheel_tf=read_bool(plugin, "publish_wheel_tf", False, where),
        odometry_frame=read_text(plugin, "odometry_frame", "odom"),
        robot_base_frame=read_text(plugin, "robot_base_frame", "base_footprint"),
        odometry_source=source,
        covariance=(
            read_float(plugin, "covariance_x", 0.00001, where),
            read_float(plugin, "covariance_y", 0.00001, where),
            read_float(plugin, "covariance_yaw", 0.001, where),
        ),
        cmd_topic=names.resolve("cmd_vel"),
        odom_topic=names.resolve("odom"),
        namespace=names.namespace,
    )


def parse_gz_diff_drive(plugin: ET.Element, model: str, root_link: str) -> DiffDriveParams:
    """gz-sim DiffDrive system: its gz topics are served on ROS directly, as if bridged."""
    where = where_of(plugin)
    left = tuple(_joint_names(plugin, "left_joint"))
    right = tuple(_joint_names(plugin, "right_joint"))
    _need_wheels(left, right, where)
    radius = positive(read_float(plugin, "wheel_radius", 0.2, where), "wheel_radius", where)
    cmd = read_text(plugin, "topic", f"/model/{model}/cmd_vel")
    odom = read_text(plugin, "odom_topic", f"/model/{model}/odometry")
    return DiffDriveParams(
        plugin=plugin.get("name", "DiffDrive"),
        left_joints=left,
        right_joints=right,
        wheel_separation=positive(
            read_float(plugin, "wheel_separation", 1.0, where), "wheel_separation", where
        ),
        wheel_diameter=2 * radius,
        max_wheel_acceleration=abs(read_float(plugin, "max_linear_acceleration", 0.0, where)),
        update_rate=read_float(plugin, "odom_publish_frequency", 50.0, where),
        publish_odom=True,
        odometry_frame=read_text(plugin, "frame_id", f"{model}/odom"),
        robot_base_frame=read_text(plugin, "child_frame_id", f"{model}/{root_link}"),
        cmd_topic=expand_topic(cmd, "/", model),
        odom_topic=expand_topic(odom, "/", model),
    )


def _joint_names(plugin: ET.Element, tag: str) -> list[str]:
    return [(e.text or "").strip() for e in plugin.findall(tag) if (e.text or "").strip()]


def _need_wheels(left: Sequence[str], right: Sequence[str], where: str) -> None:
    if not left or not right:
        raise ModelError(f"{where}: needs <left_joint> and <right_joint> naming the wheel joints")


@dataclass(frozen=True)
class JointStateParams:
    """Which joints to publish on which topic and how often."""

    topic: str
    joints: tuple[str, ...]
    update_rate: float = DEFAULT_JOINT_STATE_RATE


# ---------------------------------------------------------------- the whole model


@dataclass
class ModelSpec:
    """Everything the simulator needs to run one spawned robot."""

    name: str
    robot: Robot
    drive: DiffDriveParams | None = None
    lidars: list[LidarParams] = field(default_factory=list)
    imus: list[ImuParams] = field(default_factory=list)
    cameras: list[CameraParams] = field(default_factory=list)
    joint_states: JointStateParams | None = None
    radius: float = 0.1  # the robot's footprint as one disc around the root frame origin
    height: tuple[float, float] = (0.0, 0.3)  # z span relative to the root frame

    axle: tuple[float, float] = (
        0.0,
        0.0,
    )  # wheel-axle midpoint in the root frame: turns pivot here
    warnings: list[str] = field(default_factory=list)

    def summary(self) -> str:
        """One line for the simulator's start-up message."""
        parts = [f"model {self.name!r} (robot {self.robot.name!r}, {len(self.robot.links)} links)"]
        if self.drive:
            parts.append(f"diff drive {self.drive.cmd_topic} -> {self.drive.odom_topic}")
        parts += [f"lidar {s.topic} @{s.update_rate:g} Hz" for s in self.lidars]
        parts += [f"imu {s.topic} @{s.update_rate:g} Hz" for s in self.imus]
        parts += [
            f"depth camera {c.depth_topic} {c.width}x{c.height} {c.encoding} @{c.update_rate:g} Hz"
            for c in self.cameras
        ]
        if self.joint_states:
            parts.append(f"joint states {self.joint_states.topic}")
        return ", ".join(parts)


def describe_model(
    robot: Robot, name: str, robot_namespace: str = "", world: str = "default"
) -> ModelSpec:
    """Read a robot's ``<gazebo>`` blocks into a ModelSpec; raise ModelError on unusable ones."""
    spec = ModelSpec(name=name, robot=robot)
    js_plugin: JointStateParams | None = None
    for block in robot.gazebo:
        reference = block.get("reference")
        if reference:
            _sensors_of(spec, block, reference, robot_namespace)
            continue
        for plugin in block.findall("plugin"):
            kind = plugin_kind(plugin.get("filename", ""))
            if kind == CLASSIC_DIFF_DRIVE:
                _set_drive(spec, parse_classic_diff_drive(plugin, robot_namespace))
            elif kind in GZ_DIFF_DRIVE or plugin.get("name") == "gz::sim::systems::DiffDrive":
                _set_drive(spec, parse_gz_diff_drive(plugin, name, robot.root))
            elif kind == CLASSIC_JOINT_STATES:
                js_plugin = _classic_joint_states(plugin, robot_namespace)
            elif kind in GZ_JOINT_STATES:
                topic = read_text(plugin, "topic", f"/world/{world}/model/{name}/joint_state")
                joints = tuple(_joint_names(plugin, "joint_name"))
                js_plugin = JointStateParams(expand_topic(topic, "/", name), joints)
            else:
                spec.warnings.append(
                    f"plugin {plugin.get('filename')!r} is not simulated by the stand-in"
                )
    _check_joints(spec, js_plugin)
    spec.joint_states = js_plugin or _default_joint_states(spec, robot_namespace)
    spec.radius, spec.height = _footprint(robot)
    if spec.drive:
        spec.axle = _axle(robot, spec.drive)
    return spec


def _set_drive(spec: ModelSpec, drive: DiffDriveParams) -> None:
    if spec.drive is not None:
        raise ModelError(
            f"model {spec.name!r} has two diff-drive plugins "
            f"({spec.drive.plugin!r} and {drive.plugin!r})"
        )
    spec.drive = drive


def _classic_joint_states(plugin: ET.Element, robot_namespace: str) -> JointStateParams:
    where = where_of(plugin)
    names = parse_ros_block(plugin, robot_namespace)
    rate = read_float(plugin, "update_rate", 100.0, where)
    return JointStateParams(
        names.resolve("joint_states"), tuple(_joint_names(plugin, "joint_name")), rate
    )


def _default_joint_states(spec: ModelSpec, robot_namespace: str) -> JointStateParams | None:
    """Without a joint state plugin: the wheel joints on ``joint_states`` in the robot's namespace.

    Gazebo would leave them to a joint_state_publisher plugin; publishing them keeps
    robot_state_publisher's wheel frames alive in launch files that rely on publish_wheel_tf.
    """
    if spec.drive is None:
        return None
    namespace = robot_namespace or spec.drive.namespace
    joints = spec.drive.left_joints + spec.drive.right_joints
    return JointStateParams(expand_topic("joint_states", namespace, "gazebo"), joints)


def _check_joints(spec: ModelSpec, js: JointStateParams | None) -> None:
    joints = spec.robot.joints
    wanted: list[tuple[str, str]] = []
    if spec.drive:
        wanted += [
            (j, f"diff drive {spec.drive.plugin!r}")
            for j in spec.drive.left_joints + spec.drive.right_joints
        ]
    if js:
        wanted += [(j, "joint state publisher") for j in js.joints]
    for joint, user in wanted:
        if joint not in joints:
            raise ModelError(
                f"{user}: joint {joint!r} is not in the URDF; "
                f"joints are: {', '.join(joints) or 'none'}"
            )
        if user.startswith("diff") and joints[joint].type not in ("continuous", "revolute"):
            raise ModelError(
                f"{user}: wheel joint {joint!r} is {joints[joint].type}; "
                "it must be continuous or revolute"
            )


def _sensors_of(spec: ModelSpec, block: ET.Element, link: str, robot_namespace: str) -> None:
    sensors = block.findall("sensor")
    if sensors and link not in spec.robot.links:
        raise ModelError(
            f"<gazebo reference={link!r}> holds a sensor but the URDF has no such link; "
            f"links are: {', '.join(spec.robot.links)}"
        )
    for sensor in sensors:
        kind = sensor.get("type", "")
        mount = sensor_mount(spec.robot, link, sensor)
        if kind in LIDAR_TYPES:
            spec.lidars.append(parse_lidar(sensor, link, mount, robot_namespace))
        elif kind in IMU_TYPES:
            spec.imus.append(parse_imu(sensor, link, mount, robot_namespace))
        elif kind in DEPTH_TYPES:
            spec.cameras.append(parse_depth_camera(sensor, link, mount, robot_namespace))
        else:
            spec.warnings.append(
                f"sensor {sensor.get('name')!r} of type {kind!r} on {link!r} "
                "is not simulated (no rendering)"
            )


def sensor_mount(robot: Robot, link: str, sensor: ET.Element) -> Mount:
    """The sensor's pose in the root frame: link pose via the joint chain, then its ``<pose>``."""
    pose = _pose3(robot.link_transform(link))
    text = sensor.findtext("pose")
    if text and text.strip():
        parts = text.split()
        try:
            values = [float(p) for p in parts]
        except ValueError:
            values = []
        if len(values) != 6:
            raise ModelError(
                f"sensor {sensor.get('name')!r}: <pose> is {text.strip()!r}; expected 6 numbers"
            )
        pose = pose.compose(Pose3.from_xyz_rpy(*values))
    x, y, z = pose.xyz
    return Mount(x, y, z, pose.yaw, pose.rot[2][2] < 0)


def _footprint(robot: Robot) -> tuple[float, tuple[float, float]]:
    """One disc around the root origin covering the robot seen from above, and its z span.

    Collision geometry is used where a link has any (it is what touches the world), else its
    visual geometry; meshes are skipped (their extent is unknown without loading them).
    """
    radius, zmin, zmax = 0.0, math.inf, -math.inf
    for link in robot.links.values():
        collisions = [g for g in link.geometries if g.role == "collision"]
        chosen = collisions or [g for g in link.geometries if g.role == "visual"]
        base = _pose3(robot.link_transform(link.name)) if chosen else Pose3()
        for geom in chosen:
            shape = _geometry_shape(
                base.compose(Pose3.from_xyz_rpy(*geom.origin_xyz, *geom.origin_rpy)), geom
            )
            if shape is None:
                continue
            zmin, zmax = min(zmin, shape.zmin), max(zmax, shape.zmax)
            if isinstance(shape, Disc):
                radius = max(radius, math.hypot(shape.x, shape.y) + shape.radius)
            else:
                radius = max(radius, *(math.hypot(x, y) for x, y in shape.points))
    if not math.isfinite(zmin):
        zmin, zmax = 0.0, 0.3
    return (radius or 0.1), (zmin, zmax)


def _geometry_shape(pose: Pose3, geom: Geometry) -> Shape | None:
    if geom.kind == "box":
        return box_shape("", pose, geom.size)
    if geom.kind == "cylinder":
        return cylinder_shape("", pose, geom.size[0], geom.size[1])
    if geom.kind == "sphere":
        return sphere_shape("", pose, geom.size[0])
    return None


def _pose3(m: Sequence[Sequence[float]]) -> Pose3:
    rows = [(row[0], row[1], row[2]) for row in m[:3]]
    return Pose3((rows[0], rows[1], rows[2]), (m[0][3], m[1][3], m[2][3]))


def _axle(robot: Robot, drive: DiffDriveParams) -> tuple[float, float]:
    points = [
        robot.link_pose_in_root(robot.joints[j].child)
        for j in (drive.left_joints[0], drive.right_joints[0])
    ]
    return ((points[0][0] + points[1][0]) / 2, (points[0][1] + points[1][1]) / 2)


# ---------------------------------------------------------------- kinematics


@dataclass(frozen=True)
class Pose2D:
    """A planar pose: position and heading."""

    x: float = 0.0
    y: float = 0.0
    yaw: float = 0.0


def integrate(
    pose: Pose2D, v: float, w: float, dt: float, pivot: tuple[float, float] = (0.0, 0.0)
) -> Pose2D:
    """Move ``pose`` along the exact arc of body speeds (v, w) for dt, turning about ``pivot``.

    ``pivot`` is the wheel-axle midpoint in the pose's own frame: a diff-drive robot rotates
    about it, not about its frame origin.
    """
    c, s = math.cos(pose.yaw), math.sin(pose.yaw)
    px = pose.x + c * pivot[0] - s * pivot[1]
    py = pose.y + s * pivot[0] + c * pivot[1]
    yaw = pose.yaw + w * dt
    if abs(w) < 1e-12:
        px += v * dt * c
        py += v * dt * s
    else:
        px += v / w * (math.sin(yaw) - s)
        py -= v / w * (math.cos(yaw) - c)
    c2, s2 = math.cos(yaw), math.sin(yaw)
    yaw = math.atan2(s2, c2)
    return Pose2D(px - (c2 * pivot[0] - s2 * pivot[1]), py - (s2 * pivot[0] + c2 * pivot[1]), yaw)


@dataclass
class DiffDrive:
    """Two driven wheels: commanded body speeds, per-wheel acceleration limit, wheel angles.

    Follows gazebo_ros_diff_drive: a Twist sets target wheel rim speeds
    ``v -/+ w * separation / 2``; with ``max_wheel_acceleration`` > 0 each wheel approaches its
    target by at most that many m/s per second. The last command holds until the next one.
    """

    separation: float
    wheel_radius: float
    max_wheel_acceleration: float = 0.0
    pivot: tuple[float, float] = (0.0, 0.0)
    pose: Pose2D = field(default_factory=Pose2D)
    target_left: float = 0.0
    target_right: float = 0.0
    left_speed: float = 0.0
    right_speed: float = 0.0
    left_angle: float = 0.0
    right_angle: float = 0.0

    def command(self, linear: float, angular: float) -> None:
        """Take a cmd_vel: forward speed (m/s) and turn rate (rad/s)."""
        self.target_left = linear - angular * self.separation / 2
        self.target_right = linear + angular * self.separation / 2

    @property
    def linear(self) -> float:
        """Current forward speed of the robot (m/s)."""
        return (self.left_speed + self.right_speed) / 2

    @property
    def angular(self) -> float:
        """Current turn rate of the robot (rad/s)."""
        return (self.right_speed - self.left_speed) / self.separation

    def _approach(self, current: float, target: float, dt: float) -> float:
        limit = self.max_wheel_acceleration * dt
        if limit <= 0 or abs(target - current) <= limit:
            return target
        return current + math.copysign(limit, target - current)

    def step(self, dt: float, blocked: Callable[[Pose2D], bool] | None = None) -> bool:
        """Advance dt seconds; if ``blocked(new_pose)`` the robot stays put and its wheels stop.

        Returns whether the robot moved.
        """
        self.left_speed = self._approach(self.left_speed, self.target_left, dt)
        self.right_speed = self._approach(self.right_speed, self.target_right, dt)
        if self.left_speed == 0.0 and self.right_speed == 0.0:
            return False
        candidate = integrate(self.pose, self.linear, self.angular, dt, self.pivot)
        if blocked is not None and blocked(candidate):
            self.left_speed = self.right_speed = 0.0
            return False
        self.pose = candidate
        self.left_angle += self.left_speed / self.wheel_radius * dt
        self.right_angle += self.right_speed / self.wheel_radius * dt
        return True
