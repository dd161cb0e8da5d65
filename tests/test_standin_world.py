"""Pure tests of the simulator stand-in's world (SDF, ray casting, noise) and robot model
(plugin parameters, topic names, diff-drive kinematics). No rclpy, no processes."""

from __future__ import annotations

import math
import random
from pathlib import Path

import pytest

from mlaunch.standins.diffdrive import (
    DiffDrive,
    ModelError,
    Pose2D,
    RosNames,
    describe_model,
    expand_topic,
    integrate,
)
from mlaunch.standins.urdf import parse_urdf
from mlaunch.standins.world import (
    Disc,
    GaussianNoise,
    Polygon,
    RayCaster,
    ScanGeometry,
    World,
    WorldError,
    clearance,
    load_world,
    parse_world,
    seeded_rng,
)

WORLD = """<?xml version="1.0"?>
<sdf version="1.6">
  <world name="room">
    <gravity>0 0 -9.81</gravity>
    <include><uri>model://ground_plane</uri></include>
    <model name="ground_plane">
      <static>true</static>
      <link name="link"><collision name="c"><geometry><plane><normal>0 0 1</normal></plane>
      </geometry></collision></link>
    </model>
    <model name="wall">
      <static>true</static>
      <pose>2 0 0.5 0 0 0</pose>
      <link name="link"><collision name="c"><geometry><box><size>1 1 1</size></box></geometry>
      </collision></link>
    </model>
    <model name="post">
      <static>true</static>
      <pose>0 3 0 0 0 0</pose>
      <link name="link">
        <pose>0 0 0.5 0 0 0</pose>
        <collision name="c"><geometry><cylinder><radius>0.5</radius><length>1</length></cylinder>
        </geometry></collision>
      </link>
    </model>
    <model name="diamond">
      <static>true</static>
      <pose>-3 0 0.5 0 0 0.7853981633974483</pose>
      <link name="link"><collision name="c"><geometry><box><size>1 1 1</size></box></geometry>
      </collision></link>
    </model>
    <model name="ball">
      <static>true</static>
      <pose>0 -5 1 0 0 0</pose>
      <link name="link"><collision name="c"><geometry><sphere><radius>1</radius></sphere>
      </geometry></collision></link>
    </model>
  </world>
</sdf>
"""


def scan_at(caster: RayCaster, angle: float, z: float = 0.5, rmin: float = 0.0) -> float:
    return caster.cast(0.0, 0.0, z, angle, rmin, 10.0)


# ---------------------------------------------------------------- SDF parsing


def test_world_shapes_have_their_poses() -> None:
    world = parse_world(WORLD, "room.world")
    assert world.name == "room"
    assert world.gravity == (0.0, 0.0, -9.81)
    by_model = {s.model: s for s in world.shapes}
    assert sorted(by_model) == ["ball", "diamond", "post", "wall"]  # the ground plane is skipped
    wall = by_model["wall"]
    assert isinstance(wall, Polygon)
    corners = [c for point in sorted(wall.points) for c in point]
    assert corners == pytest.approx([1.5, -0.5, 1.5, 0.5, 2.5, -0.5, 2.5, 0.5])
    assert (wall.zmin, wall.zmax) == pytest.approx((0.0, 1.0))
    post = by_model["post"]
    assert isinstance(post, Disc)
    assert (post.x, post.y, post.radius, post.zmin, post.zmax) == pytest.approx(
        (0, 3, 0.5, 0, 1)
    )  # model pose + link pose compose
    diamond = by_model["diamond"]
    assert isinstance(diamond, Polygon)
    assert max(p[0] for p in diamond.points) == pytest.approx(-3 + math.sqrt(0.5))


def test_state_poses_override_model_poses_and_nested_models_compose() -> None:
    text = """<sdf version="1.6"><world name="w">
      <model name="box"><pose>9 9 0 0 0 0</pose>
        <link name="l"><collision name="c"><geometry><box><size>2 2 2</size></box></geometry>
        </collision></link>
        <model name="inner"><pose>1 0 0 0 0 1.5707963267948966</pose>
          <link name="l"><pose>1 0 0 0 0 0</pose><collision name="c"><geometry>
            <sphere><radius>0.25</radius></sphere></geometry></collision></link>
        </model>
      </model>
      <state world_name="w"><model name="box"><pose>1 2 1 0 0 0</pose></model></state>
    </world></sdf>"""
    shapes = {s.model: s for s in parse_world(text).shapes}
    box = shapes["box"]
    assert isinstance(box, Polygon)
    assert min(p[0] for p in box.points) == pytest.approx(0.0)
    assert min(p[1] for p in box.points) == pytest.approx(1.0)
    inner = shapes["box::inner"]
    assert isinstance(inner, Disc)
    # state pose (1, 2) + nested (1, 0) rotated 90 deg + link (1, 0) in the rotated frame
    assert (inner.x, inner.y) == pytest.approx((2.0, 3.0))


def test_include_resolves_model_path(tmp_path: Path) -> None:
    model_dir = tmp_path / "models" / "crate"
    model_dir.mkdir(parents=True)
    (model_dir / "model.sdf").write_text(
        """<sdf version="1.6"><model name="crate"><pose>50 50 0 0 0 0</pose>
        <link name="l"><collision name="c"><geometry><box><size>1 1 1</size></box></geometry>
        </collision></link></model></sdf>"""
    )
    text = """<sdf version="1.6"><world name="w">
      <include><uri>model://crate</uri><name>crate_a</name><pose>4 0 0.5 0 0 0</pose></include>
      <include><uri>model://missing</uri></include>
    </world></sdf>"""
    world = parse_world(text, "w.world", {"GAZEBO_MODEL_PATH": str(tmp_path / "models")})
    assert [s.model for s in world.shapes] == ["crate_a"]
    caster = RayCaster(world.shapes)
    assert scan_at(caster, 0.0) == pytest.approx(3.5, abs=1e-9)  # include pose wins
    assert any("model://missing" in w and "w.world:3" in w for w in world.warnings)


def test_malformed_world_names_file_and_line(tmp_path: Path) -> None:
    path = tmp_path / "bad.world"
    path.write_text('<sdf version="1.6">\n<world name="w">\n<model name="m">\n</world>\n</sdf>\n')
    with pytest.raises(WorldError) as info:
        load_world(path)
    message = str(info.value)
    assert f"{path}:4" in message and "mismatched tag" in message


def test_bad_number_names_file_line_and_value() -> None:
    text = """<sdf version="1.6">
<world name="w">
  <model name="m"><link name="l"><collision name="c"><geometry>
    <box><size>1 x 1</size></box>
  </geometry></collision></link></model>
</world></sdf>"""
    with pytest.raises(WorldError) as info:
        parse_world(text, "w.sdf")
    assert "w.sdf:4" in str(info.value) and "'1 x 1'" in str(info.value)


def test_missing_world_file_is_named(tmp_path: Path) -> None:
    with pytest.raises(WorldError) as info:
        load_world(tmp_path / "nope.world")
    assert "nope.world" in str(info.value) and "does not exist" in str(info.value)


def test_wrong_root_element() -> None:
    with pytest.raises(WorldError, match="expected <sdf>"):
        parse_world("<robot name='r'/>", "x.world")


# ---------------------------------------------------------------- ray casting


def test_ray_distances_are_exact() -> None:
    caster = RayCaster(parse_world(WORLD).shapes)
    assert scan_at(caster, 0.0) == pytest.approx(1.5, abs=1e-6)  # box face
    assert scan_at(caster, math.pi / 2) == pytest.approx(2.5, abs=1e-6)  # cylinder
    assert scan_at(caster, math.pi) == pytest.approx(3 - math.sqrt(0.5), abs=1e-6)  # box corner
    # Off-centre hit on the cylinder: ray at angle a from origin, circle centre (0, 3), r 0.5.
    a = math.pi / 2 - 0.1
    b = 3 * math.sin(a)
    expected = b - math.sqrt(b * b - (9 - 0.25))
    assert scan_at(caster, a) == pytest.approx(expected, abs=1e-6)
    assert scan_at(caster, math.radians(45)) == math.inf  # nothing there


def test_sphere_cross_section_and_height_filter() -> None:
    caster = RayCaster(parse_world(WORLD).shapes)
    down = -math.pi / 2
    assert scan_at(caster, down, z=1.0) == pytest.approx(4.0, abs=1e-6)
    assert scan_at(caster, down, z=1.6) == pytest.approx(5 - 0.8, abs=1e-6)
    assert scan_at(caster, down, z=2.5) == math.inf  # above the ball
    assert scan_at(caster, 0.0, z=1.5) == math.inf  # above the 1 m wall


def test_rays_start_at_range_min_and_stop_at_range_max() -> None:
    caster = RayCaster([Disc("d", 0.0, 0.0, 1.0, 0.0, 1.0)])
    # From inside the disc the ray leaves it at the boundary; with range_min beyond, it misses.
    assert caster.cast(0.0, 0.0, 0.5, 0.3, 0.0, 5.0) == pytest.approx(1.0)
    assert caster.cast(0.0, 0.0, 0.5, 0.3, 1.5, 5.0) == math.inf
    assert caster.cast(-3.0, 0.0, 0.5, 0.0, 0.0, 1.9) == math.inf  # 2.0 is beyond range_max


def test_scan_matches_single_rays_everywhere() -> None:
    """The per-shape angular windows of scan() must never skip a ray that hits."""
    world = parse_world(WORLD)
    caster = RayCaster(world.shapes)
    rng = random.Random(7)
    geometry = ScanGeometry(-2.0, 4.2, 91, 0.05, 8.0)
    for _ in range(25):
        x, y, yaw = rng.uniform(-4, 4), rng.uniform(-4, 4), rng.uniform(-math.pi, math.pi)
        mirrored = rng.random() < 0.3
        ranges = caster.scan(x, y, 0.5, yaw, geometry, mirrored=mirrored)
        sign = -1 if mirrored else 1
        for i, got in enumerate(ranges):
            angle = yaw + sign * (geometry.angle_min + i * geometry.increment)
            want = caster.cast(x, y, 0.5, angle, 0.05, 8.0)
            assert got == pytest.approx(want, abs=1e-9), (x, y, yaw, i)


def test_scan_increment_spans_min_to_max_inclusive() -> None:
    geometry = ScanGeometry(0.0, 6.28, 360, 0.12, 3.5)
    assert geometry.increment == pytest.approx(6.28 / 359)
    caster = RayCaster([Disc("d", 2.0, 0.0, 0.5, 0.0, 1.0)])
    ranges = caster.scan(0.0, 0.0, 0.5, 0.0, geometry)
    assert len(ranges) == 360
    assert ranges[0] == pytest.approx(1.5) and ranges[180] == math.inf


def test_clearance_of_robot_disc() -> None:
    shapes = parse_world(WORLD).shapes
    assert clearance(shapes, 0.0, 0.0, 0.25, 0.0, 0.5) == pytest.approx(1.25)
    assert clearance(shapes, 1.4, 0.0, 0.25, 0.0, 0.5) < 0
    assert clearance(shapes, 2.0, 0.0, 0.25, 0.0, 0.5) < 0  # inside the box
    assert clearance(shapes, 1.4, 0.0, 0.25, 2.0, 3.0) > 0  # the wall is below a flying robot


# ---------------------------------------------------------------- noise


def test_noise_is_deterministic_per_seed() -> None:
    noise = GaussianNoise(0.0, 0.01, 0.001, 0.0001)

    def draw(seed: int) -> list[float]:
        sampler = noise.sampler(seeded_rng(seed, "bot", "lidar"))
        return [sampler.apply(1.0) for _ in range(50)]

    assert draw(3) == draw(3)
    assert draw(3) != draw(4)
    assert seeded_rng(3, "bot", "imu").random() != seeded_rng(3, "bot", "lidar").random()


def test_noise_statistics() -> None:
    sampler = GaussianNoise(0.5, 0.2).sampler(seeded_rng(1, "x"))
    values = [sampler.apply(0.0) for _ in range(20000)]
    mean = sum(values) / len(values)
    std = math.sqrt(sum((v - mean) ** 2 for v in values) / len(values))
    assert mean == pytest.approx(0.5, abs=0.01)
    assert std == pytest.approx(0.2, rel=0.03)
    biased = GaussianNoise(0.0, 0.0, 0.3, 0.0).sampler(seeded_rng(1, "y"))
    assert abs(biased.apply(1.0) - 1.0) == pytest.approx(0.3)  # constant bias, random sign
    assert GaussianNoise().sampler(random.Random(0)).apply(2.0) == 2.0


# ---------------------------------------------------------------- diff drive kinematics


def test_straight_line() -> None:
    drive = DiffDrive(separation=0.5, wheel_radius=0.1)
    drive.command(0.5, 0.0)
    for _ in range(100):
        drive.step(0.01)
    assert (drive.pose.x, drive.pose.y, drive.pose.yaw) == pytest.approx((0.5, 0.0, 0.0))
    assert drive.left_angle == pytest.approx(5.0) and drive.right_angle == pytest.approx(5.0)


def test_turn_in_place_about_the_axle() -> None:
    drive = DiffDrive(separation=0.5, wheel_radius=0.1)
    drive.command(0.0, 1.0)
    for _ in range(100):
        drive.step(0.01)
    assert (drive.pose.x, drive.pose.y) == pytest.approx((0.0, 0.0), abs=1e-12)
    assert drive.pose.yaw == pytest.approx(1.0)
    assert drive.left_angle == pytest.approx(-2.5) and drive.right_angle == pytest.approx(2.5)
    # With the axle 0.1 m behind the frame origin the origin swings around the axle.
    pose = integrate(Pose2D(), 0.0, math.pi / 2, 1.0, pivot=(-0.1, 0.0))
    assert (pose.x, pose.y, pose.yaw) == pytest.approx((-0.1, 0.1, math.pi / 2))


def test_arc_is_exact() -> None:
    pose = integrate(Pose2D(1.0, 0.0, math.pi / 2), 1.0, 1.0, math.pi)
    assert (pose.x, pose.y) == pytest.approx((-1.0, 0.0), abs=1e-12)


def test_acceleration_limit() -> None:
    drive = DiffDrive(separation=0.5, wheel_radius=0.1, max_wheel_acceleration=1.0)
    drive.command(0.5, 0.0)
    for _ in range(20):
        drive.step(0.01)
    assert drive.linear == pytest.approx(0.2)
    for _ in range(80):
        drive.step(0.01)
    assert drive.linear == pytest.approx(0.5)
    # 50 steps accelerating by 0.01 m/s each, then 50 steps at 0.5 m/s.
    assert drive.pose.x == pytest.approx(0.01 * 0.01 * sum(range(1, 51)) + 0.25)
    drive.command(0.0, 0.0)
    drive.step(0.01)
    assert drive.linear == pytest.approx(0.49)


def test_blocked_robot_stays_and_stops() -> None:
    drive = DiffDrive(separation=0.5, wheel_radius=0.1)
    drive.command(1.0, 0.0)
    assert drive.step(0.01, blocked=lambda p: p.x > 0.05)
    for _ in range(10):
        drive.step(0.01, blocked=lambda p: p.x > 0.05)
    assert drive.pose.x == pytest.approx(0.05)
    assert drive.linear == 0.0


# ---------------------------------------------------------------- plugin parameters


URDF = """<robot name="bot">
  <link name="base_link"><collision><geometry><box size="0.4 0.3 0.1"/></geometry></collision>
  </link>
  <link name="left"><collision><origin rpy="1.5707963 0 0"/>
    <geometry><cylinder radius="0.05" length="0.04"/></geometry></collision></link>
  <link name="right"><collision><origin rpy="1.5707963 0 0"/>
    <geometry><cylinder radius="0.05" length="0.04"/></geometry></collision></link>
  <link name="mast"/>
  <link name="laser"/>
  <joint name="left_joint" type="continuous"><parent link="base_link"/><child link="left"/>
    <origin xyz="-0.1 0.175 0"/><axis xyz="0 1 0"/></joint>
  <joint name="right_joint" type="continuous"><parent link="base_link"/><child link="right"/>
    <origin xyz="-0.1 -0.175 0"/><axis xyz="0 1 0"/></joint>
  <joint name="mast_joint" type="fixed"><parent link="base_link"/><child link="mast"/>
    <origin xyz="0.1 0 0.1" rpy="0 0 1.5707963267948966"/></joint>
  <joint name="laser_joint" type="fixed"><parent link="mast"/><child link="laser"/>
    <origin xyz="0.05 0 0.05"/></joint>
  <gazebo>
    <plugin name="drive" filename="libgazebo_ros_diff_drive.so">
      <ros><namespace>/demo</namespace><remapping>cmd_vel:=cmd_teleop</remapping></ros>
      <left_joint>left_joint</left_joint><right_joint>right_joint</right_joint>
      <wheel_separation>0.35</wheel_separation><wheel_diameter>0.1</wheel_diameter>
      <max_wheel_acceleration>2.0</max_wheel_acceleration>
      <publish_odom>true</publish_odom><robot_base_frame>base_link</robot_base_frame>
    </plugin>
  </gazebo>
  <gazebo reference="laser">
    <sensor name="lidar" type="ray"><update_rate>10</update_rate>
      <pose>0 0 0.02 0 0 0</pose>
      <ray><scan><horizontal><samples>90</samples><min_angle>-1.5</min_angle>
        <max_angle>1.5</max_angle></horizontal></scan>
        <range><min>0.1</min><max>5</max></range>
        <noise><type>gaussian</type><mean>0</mean><stddev>0.01</stddev></noise></ray>
      <plugin name="scanner" filename="libgazebo_ros_ray_sensor.so">
        <ros><remapping>~/out:=scan</remapping></ros></plugin>
    </sensor>
  </gazebo>
  <gazebo reference="base_link">
    <sensor name="imu" type="imu"><update_rate>50</update_rate>
      <imu><angular_velocity><z><noise type="gaussian"><stddev>0.002</stddev></noise></z>
      </angular_velocity></imu>
      <plugin name="imu_plugin" filename="libgazebo_ros_imu_sensor.so">
        <ros><namespace>/sensors</namespace></ros></plugin>
    </sensor>
  </gazebo>
</robot>"""


def test_topic_names_follow_ros_rules() -> None:
    assert expand_topic("~/out", "/", "scanner") == "/scanner/out"
    assert expand_topic("scan", "/demo", "x") == "/demo/scan"
    assert expand_topic("/abs", "/demo", "x") == "/abs"
    names = RosNames("/demo", "drive", (("cmd_vel", "cmd_teleop"), ("~/out", "/odd")))
    assert names.resolve("cmd_vel") == "/demo/cmd_teleop"
    assert names.resolve("~/out") == "/odd"
    assert names.resolve("odom") == "/demo/odom"


def test_model_plugins_and_sensor_mounts() -> None:
    spec = describe_model(parse_urdf(URDF), "bot")
    assert spec.drive is not None
    assert spec.drive.cmd_topic == "/demo/cmd_teleop"
    assert spec.drive.odom_topic == "/demo/odom"
    assert spec.drive.wheel_separation == 0.35 and spec.drive.wheel_diameter == 0.1
    assert spec.drive.max_wheel_acceleration == 2.0
    assert spec.axle == pytest.approx((-0.1, 0.0))
    (lidar,) = spec.lidars
    assert lidar.topic == "/scan" and lidar.frame_id == "laser"
    assert lidar.update_rate == 10 and lidar.scan.samples == 90
    assert lidar.noise.stddev == 0.01
    # mast at (0.1, 0, 0.1) turned 90 deg; laser 0.05 along the mast's x; sensor pose +0.02 z
    assert (lidar.mount.x, lidar.mount.y, lidar.mount.z) == pytest.approx((0.1, 0.05, 0.17))
    assert lidar.mount.yaw == pytest.approx(math.pi / 2)
    (imu,) = spec.imus
    assert imu.topic == "/sensors/imu_plugin/out"  # ~/out with no remapping
    assert imu.angular_velocity[2].stddev == 0.002
    assert spec.joint_states is not None and spec.joint_states.topic == "/demo/joint_states"
    assert spec.joint_states.joints == ("left_joint", "right_joint")
    assert spec.radius == pytest.approx(math.hypot(0.2, 0.15))
    assert spec.height[0] == pytest.approx(-0.05)


def test_robot_namespace_replaces_plugin_namespaces() -> None:
    spec = describe_model(parse_urdf(URDF), "bot", robot_namespace="/r2")
    assert spec.drive is not None and spec.drive.cmd_topic == "/r2/cmd_teleop"
    assert spec.lidars[0].topic == "/r2/scan"


def test_bad_plugin_parameters_are_named() -> None:
    broken = URDF.replace("<left_joint>left_joint</left_joint>", "<left_joint>nope</left_joint>")
    with pytest.raises(ModelError, match="joint 'nope' is not in the URDF"):
        describe_model(parse_urdf(broken), "bot")
    broken = URDF.replace("<wheel_separation>0.35", "<wheel_separation>wide")
    with pytest.raises(ModelError, match=r"<wheel_separation> is 'wide', not a number"):
        describe_model(parse_urdf(broken), "bot")
    broken = URDF.replace('<gazebo reference="laser">', '<gazebo reference="lazer">')
    with pytest.raises(ModelError, match="no such link"):
        describe_model(parse_urdf(broken), "bot")


def test_empty_world_summary() -> None:
    assert "0 shapes" in World().summary()


def test_gz_sim_diff_drive_and_lidar_topics() -> None:
    text = """<robot name="gzbot">
      <link name="chassis"/><link name="l"/><link name="r"/><link name="lidar_link"/>
      <joint name="lj" type="continuous"><parent link="chassis"/><child link="l"/>
        <origin xyz="0 0.2 0"/></joint>
      <joint name="rj" type="continuous"><parent link="chassis"/><child link="r"/>
        <origin xyz="0 -0.2 0"/></joint>
      <joint name="lidar_joint" type="fixed"><parent link="chassis"/><child link="lidar_link"/>
      </joint>
      <gazebo>
        <plugin filename="gz-sim-diff-drive-system" name="gz::sim::systems::DiffDrive">
          <left_joint>lj</left_joint><right_joint>rj</right_joint>
          <wheel_separation>0.4</wheel_separation><wheel_radius>0.06</wheel_radius>
          <topic>cmd_vel</topic>
        </plugin>
        <plugin filename="libsomething_else.so" name="x"/>
      </gazebo>
      <gazebo reference="lidar_link">
        <sensor name="gpu_lidar" type="gpu_lidar"><topic>scan</topic><update_rate>8</update_rate>
          <lidar><scan><horizontal><samples>10</samples><min_angle>-1</min_angle>
            <max_angle>1</max_angle></horizontal></scan><range><min>0.1</min><max>9</max></range>
          </lidar>
        </sensor>
      </gazebo>
    </robot>"""
    spec = describe_model(parse_urdf(text), "gzbot")
    assert spec.drive is not None
    assert spec.drive.cmd_topic == "/cmd_vel"
    assert spec.drive.odom_topic == "/model/gzbot/odometry"
    assert spec.drive.wheel_diameter == pytest.approx(0.12)
    assert spec.drive.robot_base_frame == "gzbot/chassis" and spec.drive.publish_odom
    assert spec.lidars[0].topic == "/scan" and spec.lidars[0].frame_id == "lidar_link"
    assert spec.warnings == ["plugin 'libsomething_else.so' is not simulated by the stand-in"]
