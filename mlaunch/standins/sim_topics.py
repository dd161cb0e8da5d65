"""The simulator's topics: one publisher and one reused message per output of a spawned robot.

``make_outputs`` turns a robot's plugin blocks into periodic ``Output``s (odometry, the odom ->
base transform, joint states, scans, IMU, the depth camera); the simulator's loop calls each one
when its sim-time schedule is due. rclpy and the message types are imported inside the functions.
"""

from __future__ import annotations

import array
import math
import sys
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from mlaunch.standins.camera import CameraParams, DepthRenderer, camera_info
from mlaunch.standins.diffdrive import Pose2D
from mlaunch.standins.sensors import ImuParams, LidarParams
from mlaunch.standins.simulation import Schedule, SimRobot, Simulation

PROG = "mlaunch sim"


def say(message: str) -> None:
    """One plain line on stdout (start-up and spawn notes)."""
    print(f"{PROG}: {message}", flush=True)


def warn(message: str) -> None:
    """One plain line on stderr."""
    print(f"{PROG}: warning: {message}", file=sys.stderr, flush=True)


def make_publisher(node: Any, msg_type: Any, topic: str, qos: Any) -> Any:
    """A publisher without rclpy's default QoS-event handlers.

    Each default handler joins every wait set, and rclpy rebuilds the wait set on each spin:
    with a dozen topics that was most of the simulator's CPU time at 100 steps per second.
    """
    from rclpy.event_handler import PublisherEventCallbacks

    callbacks = PublisherEventCallbacks(use_default_callbacks=False)
    return node.create_publisher(msg_type, topic, qos, event_callbacks=callbacks)


def make_subscription(node: Any, msg_type: Any, topic: str, callback: Any, qos: Any) -> Any:
    """A subscription without rclpy's default QoS-event handlers (see make_publisher)."""
    from rclpy.event_handler import SubscriptionEventCallbacks

    callbacks = SubscriptionEventCallbacks(use_default_callbacks=False)
    return node.create_subscription(msg_type, topic, callback, qos, event_callbacks=callbacks)


@dataclass
class Output:
    """One periodic publication: when (sim-time schedule) and how (a closure over a message)."""

    schedule: Schedule
    publish: Callable[[int, int], None]


def tf_support() -> Any:
    """tf2_msgs' TFMessage when installed (it is not in the PyPI ROS wheels), else None."""
    try:
        from tf2_msgs.msg import TFMessage
    except ImportError:
        return None
    return TFMessage


def make_outputs(node: Any, sim: Simulation, robot: SimRobot, qos: Any, tf: Any) -> list[Output]:
    """Publishers and closures for every topic a spawned robot serves (cmd_vel apart)."""
    spec = robot.spec
    outputs: list[Output] = []
    start = sim.now_ns
    if spec.drive and robot.drive:
        if spec.drive.publish_odom:
            outputs.append(
                Output(
                    Schedule.every(spec.drive.update_rate, start), _odom_publisher(node, robot, qos)
                )
            )
        if tf is not None and spec.drive.publish_odom_tf:
            outputs.append(
                Output(
                    Schedule.every(spec.drive.update_rate, start), _tf_publisher(node, robot, tf)
                )
            )
    if spec.joint_states:
        outputs.append(
            Output(
                Schedule.every(spec.joint_states.update_rate, start),
                _joint_state_publisher(node, robot, qos),
            )
        )
    for lidar in spec.lidars:
        outputs.append(
            Output(
                Schedule.every(lidar.update_rate, start),
                _scan_publisher(node, sim, robot, lidar, qos),
            )
        )
    for imu in spec.imus:
        outputs.append(
            Output(
                Schedule.every(imu.update_rate, start), _imu_publisher(node, sim, robot, imu, qos)
            )
        )
    for camera in spec.cameras:
        outputs.append(
            Output(
                Schedule.every(camera.update_rate, start),
                _depth_camera_publisher(node, sim, robot, camera, qos),
            )
        )
    return outputs


def subscribe_cmd_vel(node: Any, robot: SimRobot, stamped: bool = False) -> Any:
    """The robot's diff-drive command subscription: geometry_msgs Twist, or TwistStamped where a
    bridge says its ROS side has that type (ros_gz_bridge's configs of Jazzy robots do)."""
    from geometry_msgs.msg import Twist, TwistStamped

    spec, drive = robot.spec, robot.drive
    assert spec.drive is not None and drive is not None
    warned = [False]

    def on_twist(msg: Any) -> None:
        if stamped:
            msg = msg.twist
        linear, angular = msg.linear.x, msg.angular.z
        if not (math.isfinite(linear) and math.isfinite(angular)):
            if not warned[0]:
                warn(f"model {spec.name!r}: ignoring non-finite cmd_vel ({linear}, {angular})")
                warned[0] = True
            return
        drive.command(linear, angular)

    kind = TwistStamped if stamped else Twist
    return make_subscription(node, kind, spec.drive.cmd_topic, on_twist, 10)


def _quaternion(msg: Any, yaw: float) -> None:
    msg.x = 0.0
    msg.y = 0.0
    msg.z = math.sin(yaw / 2)
    msg.w = math.cos(yaw / 2)


def _odom_publisher(node: Any, robot: SimRobot, qos: Any) -> Callable[[int, int], None]:
    from nav_msgs.msg import Odometry

    params = robot.spec.drive
    drive = robot.drive
    assert params is not None and drive is not None
    msg = Odometry()
    msg.header.frame_id = params.odometry_frame
    msg.child_frame_id = params.robot_base_frame
    cx, cy, cyaw = params.covariance
    covariance = [0.0] * 36
    covariance[0], covariance[7], covariance[35] = cx, cy, cyaw
    covariance[14] = covariance[21] = covariance[28] = 1e12  # z, roll, pitch are not estimated
    msg.pose.covariance = covariance
    msg.twist.covariance = covariance
    msg.pose.pose.position.z = robot.z
    publisher = make_publisher(node, Odometry, params.odom_topic, qos)
    spawn = robot.spawn

    def publish(sec: int, nanosec: int) -> None:
        pose = drive.pose
        if params.odometry_source == 0:  # encoder odometry starts at zero where it was spawned
            dx, dy = pose.x - spawn.x, pose.y - spawn.y
            c, s = math.cos(-spawn.yaw), math.sin(-spawn.yaw)
            pose = Pose2D(c * dx - s * dy, s * dx + c * dy, pose.yaw - spawn.yaw)
        msg.header.stamp.sec = sec
        msg.header.stamp.nanosec = nanosec
        msg.pose.pose.position.x = pose.x
        msg.pose.pose.position.y = pose.y
        _quaternion(msg.pose.pose.orientation, pose.yaw)
        msg.twist.twist.linear.x = drive.linear
        msg.twist.twist.angular.z = drive.angular
        publisher.publish(msg)

    return publish


def _tf_publisher(node: Any, robot: SimRobot, tf_type: Any) -> Callable[[int, int], None]:
    from geometry_msgs.msg import TransformStamped

    params = robot.spec.drive
    drive = robot.drive
    assert params is not None and drive is not None
    transform = TransformStamped()
    transform.header.frame_id = params.odometry_frame
    transform.child_frame_id = params.robot_base_frame
    transform.transform.translation.z = robot.z
    msg = tf_type()
    publisher = make_publisher(node, tf_type, "/tf", 100)

    def publish(sec: int, nanosec: int) -> None:
        transform.header.stamp.sec = sec
        transform.header.stamp.nanosec = nanosec
        transform.transform.translation.x = drive.pose.x
        transform.transform.translation.y = drive.pose.y
        _quaternion(transform.transform.rotation, drive.pose.yaw)
        msg.transforms = [transform]
        publisher.publish(msg)

    return publish


def _joint_state_publisher(node: Any, robot: SimRobot, qos: Any) -> Callable[[int, int], None]:
    from sensor_msgs.msg import JointState

    spec = robot.spec
    assert spec.joint_states is not None
    names = list(spec.joint_states.joints) or [j.name for j in spec.robot.movable_joints()]
    left = set(spec.drive.left_joints) if spec.drive else set()
    right = set(spec.drive.right_joints) if spec.drive else set()
    msg = JointState()
    msg.name = names
    publisher = make_publisher(node, JointState, spec.joint_states.topic, qos)
    drive = robot.drive

    def publish(sec: int, nanosec: int) -> None:
        positions = [0.0] * len(names)
        velocities = [0.0] * len(names)
        if drive is not None:
            radius = drive.wheel_radius
            for i, joint in enumerate(names):
                if joint in left:
                    positions[i], velocities[i] = drive.left_angle, drive.left_speed / radius
                elif joint in right:
                    positions[i], velocities[i] = drive.right_angle, drive.right_speed / radius
        msg.header.stamp.sec = sec
        msg.header.stamp.nanosec = nanosec
        msg.position = array.array("d", positions)
        msg.velocity = array.array("d", velocities)
        publisher.publish(msg)

    return publish


def _scan_publisher(
    node: Any, sim: Simulation, robot: SimRobot, lidar: LidarParams, qos: Any
) -> Callable[[int, int], None]:
    from sensor_msgs.msg import LaserScan

    msg = LaserScan()
    msg.header.frame_id = lidar.frame_id
    msg.angle_min = lidar.scan.angle_min
    msg.angle_max = lidar.scan.angle_max
    msg.angle_increment = lidar.scan.increment
    msg.time_increment = 0.0
    msg.scan_time = 0.0 if lidar.update_rate <= 0 else 1.0 / lidar.update_rate
    msg.range_min = lidar.scan.range_min
    msg.range_max = lidar.scan.range_max
    msg.intensities = array.array("f", [0.0] * lidar.scan.samples)
    publisher = make_publisher(node, LaserScan, lidar.topic, qos)

    def publish(sec: int, nanosec: int) -> None:
        msg.header.stamp.sec = sec
        msg.header.stamp.nanosec = nanosec
        msg.ranges = array.array("f", sim.scan(robot, lidar))
        publisher.publish(msg)

    return publish


def _imu_publisher(
    node: Any, sim: Simulation, robot: SimRobot, imu: ImuParams, qos: Any
) -> Callable[[int, int], None]:
    from sensor_msgs.msg import Imu

    msg = Imu()
    msg.header.frame_id = imu.frame_id
    gyro = [0.0] * 9
    accel = [0.0] * 9
    for i in range(3):
        gyro[4 * i] = imu.angular_velocity[i].stddev ** 2
        accel[4 * i] = imu.linear_acceleration[i].stddev ** 2
    msg.angular_velocity_covariance = gyro
    msg.linear_acceleration_covariance = accel
    publisher = make_publisher(node, Imu, imu.topic, qos)

    def publish(sec: int, nanosec: int) -> None:
        yaw, (wx, wy, wz, ax, ay, az) = sim.imu(robot, imu)
        msg.header.stamp.sec = sec
        msg.header.stamp.nanosec = nanosec
        _quaternion(msg.orientation, yaw)
        msg.angular_velocity.x, msg.angular_velocity.y, msg.angular_velocity.z = wx, wy, wz
        msg.linear_acceleration.x, msg.linear_acceleration.y, msg.linear_acceleration.z = ax, ay, az
        publisher.publish(msg)

    return publish


def _depth_camera_publisher(
    node: Any, sim: Simulation, robot: SimRobot, camera: CameraParams, qos: Any
) -> Callable[[int, int], None]:
    """Depth image, its camera info and the point cloud of one depth camera.

    The image and the cloud are ray-cast only when someone subscribes to them (the camera info
    goes out every frame): a 640x480 frame costs milliseconds the simulator's loop must not
    spend for nobody.
    """
    from sensor_msgs.msg import CameraInfo, Image, PointCloud2, PointField

    renderer = DepthRenderer(camera, sim.world.shapes)
    image = Image(height=camera.height, width=camera.width, encoding=camera.encoding)
    image.header.frame_id = camera.frame_id
    image.step = camera.width * (2 if camera.encoding == "16UC1" else 4)
    info = camera_info(camera, CameraInfo())
    cloud = PointCloud2(height=camera.height, width=camera.width, is_dense=False)
    cloud.header.frame_id = camera.frame_id
    cloud.fields = [
        PointField(name=axis, offset=4 * i, datatype=PointField.FLOAT32, count=1)
        for i, axis in enumerate("xyz")
    ]
    cloud.point_step, cloud.row_step = 12, 12 * camera.width
    image_pub = make_publisher(node, Image, camera.depth_topic, qos)
    info_pub = make_publisher(node, CameraInfo, camera.depth_info_topic, qos)
    cloud_pub = make_publisher(node, PointCloud2, camera.points_topic, qos)

    def publish(sec: int, nanosec: int) -> None:
        for msg in (image, info, cloud):
            msg.header.stamp.sec = sec
            msg.header.stamp.nanosec = nanosec
        info_pub.publish(info)
        want_image = image_pub.get_subscription_count() > 0
        want_cloud = cloud_pub.get_subscription_count() > 0
        if not (want_image or want_cloud):
            return
        x, y, z, yaw = sim.sensor_pose(robot, camera.mount)
        depth = renderer.render(x, y, z, yaw, sim.others(robot))
        if want_image:
            image.data = array.array("B", renderer.image_bytes(depth))
            image_pub.publish(image)
        if want_cloud:
            cloud.data = array.array("B", renderer.cloud_bytes(depth))
            cloud_pub.publish(cloud)

    return publish
