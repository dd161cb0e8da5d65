"""The stand-ins' URDF parser: a valid robot, each validation error's message, poses, footprint."""

from __future__ import annotations

import math

import pytest

from mlaunch.standins.urdf import Circle, Polygon, UrdfError, parse_urdf

# A small jtbot-like robot: footprint root, a box body lifted 0.1 m, two wheels on continuous
# joints (cylinders rolled onto their side), a caster sphere, a laser turned 90 degrees and a
# camera on a pitched, yawed mount, plus a <gazebo> block for the simulator.
ROBOT = """<?xml version="1.0"?>
<robot name="jtbot">
  <link name="base_footprint"/>
  <link name="base_link">
    <visual><geometry><box size="0.6 0.4 0.12"/></geometry></visual>
    <collision><geometry><box size="0.6 0.4 0.12"/></geometry></collision>
  </link>
  <link name="left_wheel">
    <visual><origin rpy="1.5707963267948966 0 0"/>
      <geometry><cylinder radius="0.0775" length="0.06"/></geometry></visual>
  </link>
  <link name="right_wheel">
    <collision><origin rpy="1.5707963267948966 0 0"/>
      <geometry><cylinder radius="0.0775" length="0.06"/></geometry></collision>
  </link>
  <link name="caster"><visual><geometry><sphere radius="0.03"/></geometry></visual></link>
  <link name="laser_link">
    <visual><geometry><cylinder radius="0.04" length="0.05"/></geometry></visual>
  </link>
  <link name="mount"/>
  <link name="camera_link">
    <visual><geometry><mesh filename="package://jtbot/meshes/cam.dae"/></geometry></visual>
  </link>
  <joint name="base_joint" type="fixed">
    <parent link="base_footprint"/><child link="base_link"/><origin xyz="0 0 0.1"/>
  </joint>
  <joint name="left_wheel_joint" type="continuous">
    <parent link="base_link"/><child link="left_wheel"/>
    <origin xyz="0 0.26 -0.02"/><axis xyz="0 1 0"/>
  </joint>
  <joint name="right_wheel_joint" type="continuous">
    <parent link="base_link"/><child link="right_wheel"/>
    <origin xyz="0 -0.26 -0.02"/><axis xyz="0 2 0"/>
  </joint>
  <joint name="caster_joint" type="fixed">
    <parent link="base_link"/><child link="caster"/><origin xyz="0.22 0 -0.07"/>
  </joint>
  <joint name="laser_joint" type="fixed">
    <parent link="base_link"/><child link="laser_link"/>
    <origin xyz="0.15 0 0.1" rpy="0 0 1.5707963267948966"/>
  </joint>
  <joint name="mount_joint" type="revolute">
    <parent link="base_link"/><child link="mount"/>
    <origin xyz="-0.2 0 0.1" rpy="0 0 3.141592653589793"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
  <joint name="camera_joint" type="fixed">
    <parent link="mount"/><child link="camera_link"/><origin xyz="0.1 0 0" rpy="0 0.5 0"/>
  </joint>
  <gazebo reference="laser_link"><sensor name="laser" type="ray"/></gazebo>
  <gazebo><plugin name="diff_drive" filename="libgazebo_ros_diff_drive.so"/></gazebo>
</robot>
"""


def tree(joints: str, links: str = "a b c") -> str:
    """A robot with the given links (no geometry) and joint XML."""
    link_xml = "".join(f'<link name="{name}"/>' for name in links.split())
    return f'<robot name="t">{link_xml}{joints}</robot>'


def joint(name: str, parent: str, child: str, kind: str = "fixed") -> str:
    return (
        f'<joint name="{name}" type="{kind}">'
        f'<parent link="{parent}"/><child link="{child}"/></joint>'
    )


def test_parses_links_joints_root_and_gazebo() -> None:
    robot = parse_urdf(ROBOT)
    assert robot.name == "jtbot"
    assert robot.root == "base_footprint"
    assert list(robot.links)[:3] == ["base_footprint", "base_link", "left_wheel"]
    assert [j.name for j in robot.movable_joints()] == [
        "left_wheel_joint",
        "right_wheel_joint",
        "mount_joint",
    ]
    wheel = robot.joints["right_wheel_joint"]
    assert (wheel.parent, wheel.child, wheel.type) == ("base_link", "right_wheel", "continuous")
    assert wheel.origin_xyz == (0.0, -0.26, -0.02)
    assert wheel.axis == (0.0, 1.0, 0.0)  # normalised
    assert robot.joints["mount_joint"].lower == -1.0
    body = robot.links["base_link"].geometries
    assert [(g.kind, g.role, g.size) for g in body] == [
        ("box", "visual", (0.6, 0.4, 0.12)),
        ("box", "collision", (0.6, 0.4, 0.12)),
    ]
    (mesh,) = robot.links["camera_link"].geometries
    assert (mesh.kind, mesh.size, mesh.filename) == (
        "mesh",
        (1.0, 1.0, 1.0),
        "package://jtbot/meshes/cam.dae",
    )
    assert [g.get("reference") for g in robot.gazebo] == ["laser_link", None]
    assert robot.gazebo[1].find("plugin") is not None


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        (tree(joint("j1", "a", "b")), "2 root links ['a', 'c']"),
        (tree(joint("j1", "a", "b") + joint("j2", "a", "ghost")), "joint 'j2': child link 'ghost'"),
        (tree(joint("j1", "nowhere", "b")), "joint 'j1': parent link 'nowhere' does not exist"),
        (
            tree(joint("j1", "a", "b") + joint("j2", "b", "c") + joint("j3", "c", "b"), "a b c"),
            "link 'b' has two parents",
        ),
        (
            tree(joint("j1", "a", "b") + joint("j2", "b", "c") + joint("j3", "c", "a")),
            "cycle: 'a' -> 'b' -> 'c' -> 'a'",
        ),
        (
            tree(joint("j1", "b", "c") + joint("j2", "c", "b"), "r b c"),
            "cycle: 'b' -> 'c' -> 'b'",
        ),
        (
            tree(joint("j1", "a", "b", "hinge") + joint("j2", "a", "c")),
            "joint 'j1' has type 'hinge'",
        ),
        (tree(joint("j1", "a", "b") + joint("j1", "a", "c")), "joint 'j1' is defined twice"),
        (tree(joint("j1", "a", "b", "revolute") + joint("j2", "a", "c")), "has no <limit>"),
        ('<robot name="t"><link name="a"/><link name="a"/></robot>', "link 'a' is defined twice"),
        ('<robot><link name="a"/></robot>', "<robot> has no name"),
        ('<robot name="t"><link name="a">', "not well-formed XML"),
        ("", "robot_description is empty"),
        ('<model name="t"/>', "root element is <model>"),
        (
            '<robot name="t"><link name="a"><visual><origin xyz="0 ${w} 0"/>'
            '<geometry><box size="1 1 1"/></geometry></visual></link></robot>',
            "link 'a' <visual>: origin xyz is '${w}', not a number",
        ),
        (
            '<robot name="t"><link name="a"><visual><geometry><box size="1 1"/></geometry>'
            "</visual></link></robot>",
            "link 'a' <visual>: box size is '1 1'; expected 3 numbers",
        ),
        (
            '<robot name="t"><link name="a"><collision><geometry><sphere radius="-1"/>'
            "</geometry></collision></link></robot>",
            "sphere radius is (-1.0,); sizes must be positive",
        ),
        (
            '<robot name="t"><link name="a"><visual><geometry/></visual></link></robot>',
            "must hold exactly one of box/cylinder/sphere/mesh",
        ),
    ],
)
def test_invalid_urdf_is_refused_with_a_clear_message(text: str, expected: str) -> None:
    with pytest.raises(UrdfError) as caught:
        parse_urdf(text)
    message = str(caught.value)
    assert expected in message
    assert "\n" not in message  # one line, ready for a log


def test_two_roots_message_says_how_to_fix() -> None:
    with pytest.raises(UrdfError, match="exactly one link may have no parent"):
        parse_urdf(tree("", "a b"))


def test_bad_joint_type_lists_the_valid_ones() -> None:
    with pytest.raises(UrdfError, match="valid types are: revolute, continuous, prismatic, fixed"):
        parse_urdf(tree(joint("j1", "a", "b", "slider") + joint("j2", "a", "c")))


def approx(pose: tuple[float, ...], expected: tuple[float, ...]) -> bool:
    """(x, y, z, yaw) equal within 1e-9, yaw compared modulo a full turn (pi == -pi)."""
    *xyz, yaw = pose
    *exyz, eyaw = expected
    close = all(math.isclose(v, e, abs_tol=1e-9) for v, e in zip(xyz, exyz, strict=True))
    return close and abs(math.remainder(yaw - eyaw, 2 * math.pi)) < 1e-9


def test_link_pose_in_root_composes_origins() -> None:
    robot = parse_urdf(ROBOT)
    assert approx(robot.link_pose_in_root("base_footprint"), (0, 0, 0, 0))
    assert approx(robot.link_pose_in_root("left_wheel"), (0, 0.26, 0.08, 0))
    assert approx(robot.link_pose_in_root("laser_link"), (0.15, 0, 0.2, math.pi / 2))
    # mount turned 180 degrees: the camera's +0.1 m x offset points backwards
    assert approx(robot.link_pose_in_root("camera_link"), (-0.3, 0, 0.2, math.pi))


def test_link_pose_follows_joint_positions() -> None:
    robot = parse_urdf(ROBOT)
    # The mount turns about z: the camera swings around it and its heading turns with it.
    x, y, z, yaw = robot.link_pose_in_root("camera_link", {"mount_joint": math.pi / 2})
    assert approx((x, y, z, yaw), (-0.2, -0.1, 0.2, -math.pi / 2))
    # A wheel spinning about its axle does not move its origin or its heading.
    assert approx(
        robot.link_pose_in_root("left_wheel", {"left_wheel_joint": 1.0}), (0, 0.26, 0.08, 0)
    )


def test_full_rpy_composition_matches_rotation_order() -> None:
    # roll 90 then yaw 90 (fixed axes): the child's x axis ends up along the parent's y.
    text = tree(
        '<joint name="j" type="fixed"><parent link="a"/><child link="b"/>'
        '<origin xyz="1 2 3" rpy="1.5707963267948966 0 1.5707963267948966"/></joint>'
        + joint("k", "b", "c"),
    )
    assert approx(parse_urdf(text).link_pose_in_root("c"), (1, 2, 3, math.pi / 2))


def test_unknown_link_pose_names_the_links() -> None:
    with pytest.raises(UrdfError, match="unknown link 'nope'"):
        parse_urdf(ROBOT).link_pose_in_root("nope")


def test_footprint_projects_visuals_top_down() -> None:
    robot = parse_urdf(ROBOT)
    shapes = {s.link: s for s in robot.footprint()}
    # the mesh camera cannot be outlined; links without geometry give nothing
    assert set(shapes) == {"base_link", "left_wheel", "right_wheel", "caster", "laser_link"}
    body = shapes["base_link"]
    assert isinstance(body, Polygon)
    assert sorted(body.points) == [(-0.3, -0.2), (-0.3, 0.2), (0.3, -0.2), (0.3, 0.2)]
    # a wheel lying on its side is a rectangle: diameter along x, width along y
    wheel = shapes["left_wheel"]
    assert isinstance(wheel, Polygon)
    xs = [p[0] for p in wheel.points]
    ys = [p[1] for p in wheel.points]
    assert math.isclose(min(xs), -0.0775) and math.isclose(max(xs), 0.0775)
    assert math.isclose(min(ys), 0.23) and math.isclose(max(ys), 0.29)
    # right wheel has collision geometry only: used as the fallback
    assert isinstance(shapes["right_wheel"], Polygon)
    assert max(p[1] for p in shapes["right_wheel"].points) == pytest.approx(-0.23)
    assert shapes["caster"] == Circle("caster", 0.22, 0.0, 0.03)
    laser = shapes["laser_link"]
    assert isinstance(laser, Circle)  # an upright cylinder seen from above
    assert (laser.x, laser.radius) == (pytest.approx(0.15), 0.04)


def test_footprint_rotates_with_the_link_yaw() -> None:
    text = (
        '<robot name="t"><link name="a"/><link name="b"><visual>'
        '<geometry><box size="1 0.2 0.1"/></geometry></visual></link>'
        '<joint name="j" type="fixed"><parent link="a"/><child link="b"/>'
        '<origin xyz="2 0 0" rpy="0 0 1.5707963267948966"/></joint></robot>'
    )
    (shape,) = parse_urdf(text).footprint()
    assert isinstance(shape, Polygon)
    xs = [p[0] for p in shape.points]
    ys = [p[1] for p in shape.points]
    # turned 90 degrees: the long side now runs along y
    assert (min(xs), max(xs)) == (pytest.approx(1.9), pytest.approx(2.1))
    assert (min(ys), max(ys)) == (pytest.approx(-0.5), pytest.approx(0.5))
    assert shape.to_json()["type"] == "polygon"
