"""The robot description packages mlaunch ships: jtbot (ROS 2) and smartcar (ROS 1 style).

Pure and fast, no rclpy: the xacros are processed with the real xacro package, each URDF is
checked as a kinematic tree with physical inertias, the Gazebo plugin figures against the xacro
properties they are derived from (and the seeds' numbers), and jtbot's world against what its
lidar should see from the spawn point and after driving 1 m forward.
"""

from __future__ import annotations

import importlib.util
import math
import os
import re
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest
import xacro
import yaml

REPO = Path(__file__).resolve().parent.parent
JTBOT = REPO / "robots" / "jtbot_description"
JTBOT_XACRO = JTBOT / "urdf" / "jtbot.urdf.xacro"
SMARTCAR = REPO / "robots" / "smartcar_description"
SMARTCAR_XACRO = SMARTCAR / "urdf" / "smartcar.urdf.xacro"
XACRO_NS = "{http://ros.org/wiki/xacro}"

# xacro resolves $(find pkg) through ament_index_python (the `ros` extra installs it).
requires_ament_index = pytest.mark.skipif(
    importlib.util.find_spec("ament_index_python") is None,
    reason="ament_index_python is not installed: pip install -e '.[ros]' for $(find) lookups",
)


# ---------------------------------------------------------------- processing and reading


def process(path: Path | str, **mappings: str) -> ET.Element:
    """Run the real xacro on a file (with name:=value args) and return the URDF's <robot>."""
    doc = xacro.process_file(str(path), mappings=mappings)
    return ET.fromstring(doc.toxml())


def canonical(robot: ET.Element) -> str:
    """The URDF as canonical XML without layout whitespace, to compare two processings."""
    return ET.canonicalize(ET.tostring(robot, encoding="unicode"), strip_text=True)


def xacro_properties(*paths: Path) -> dict[str, str]:
    """The raw `xacro:property` values (unevaluated text) declared in the given source files."""
    props: dict[str, str] = {}
    for path in paths:
        for elem in ET.parse(path).getroot().iter(f"{XACRO_NS}property"):
            props[elem.get("name", "")] = elem.get("value", "")
    return props


def literal(props: dict[str, str], name: str) -> float:
    """A property that must be a plain number (the constants one edits to get another robot)."""
    assert name in props, f"property {name!r} not declared; have {sorted(props)}"
    try:
        return float(props[name])
    except ValueError:
        raise AssertionError(f"property {name!r} is {props[name]!r}, expected a number")


def floats(text: str | None) -> list[float]:
    """Space-separated numbers of an attribute such as xyz, rpy or size."""
    assert text is not None, "missing numeric attribute"
    return [float(part) for part in text.split()]


def child(elem: ET.Element, path: str) -> ET.Element:
    """The element at `path` below `elem`, failing with the path when it is missing."""
    found = elem.find(path)
    assert found is not None, f"<{elem.tag} {elem.attrib}> has no {path!r}"
    return found


def text(elem: ET.Element, path: str) -> str:
    """The stripped text of the element at `path`."""
    return (child(elem, path).text or "").strip()


def number(elem: ET.Element, path: str) -> float:
    """The text of the element at `path` as a float."""
    return float(text(elem, path))


def attr(elem: ET.Element, path: str, name: str) -> float:
    """A numeric attribute of the element at `path` (e.g. a geometry's radius)."""
    value = child(elem, path).get(name)
    assert value is not None, f"{path!r} has no attribute {name!r}"
    return float(value)


def link_names(robot: ET.Element) -> list[str]:
    """Every link name, in document order."""
    return [link.get("name", "") for link in robot.findall("link")]


def joint(robot: ET.Element, name: str) -> ET.Element:
    """The joint called `name`."""
    return child(robot, f"joint[@name='{name}']")


def link(robot: ET.Element, name: str) -> ET.Element:
    """The link called `name`."""
    return child(robot, f"link[@name='{name}']")


def plugin(robot: ET.Element, filename: str) -> ET.Element:
    """The one Gazebo plugin loaded from `filename`, wherever it sits."""
    found = [p for p in robot.iter("plugin") if p.get("filename") == filename]
    assert len(found) == 1, f"expected one plugin {filename!r}, found {len(found)}"
    return found[0]


def sensor(robot: ET.Element, kind: str) -> tuple[str, ET.Element]:
    """The one Gazebo sensor of type `kind` and the link its <gazebo reference> names."""
    found = [
        (gazebo.get("reference", ""), s)
        for gazebo in robot.findall("gazebo")
        for s in gazebo.findall("sensor")
        if s.get("type") == kind
    ]
    assert len(found) == 1, f"expected one {kind!r} sensor, found {len(found)}"
    return found[0]


def rotation(rpy: list[float]) -> list[list[float]]:
    """The URDF rotation matrix Rz(yaw) Ry(pitch) Rx(roll)."""
    cr, sr = math.cos(rpy[0]), math.sin(rpy[0])
    cp, sp = math.cos(rpy[1]), math.sin(rpy[1])
    cy, sy = math.cos(rpy[2]), math.sin(rpy[2])
    return [
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ]


def origin(elem: ET.Element) -> tuple[list[float], list[float]]:
    """The xyz and rpy of an element's <origin> (URDF defaults: zeros)."""
    found = elem.find("origin")
    if found is None:
        return [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]
    return floats(found.get("xyz", "0 0 0")), floats(found.get("rpy", "0 0 0"))


def offset_from_root(robot: ET.Element, name: str) -> list[float]:
    """Where a link's frame sits in the root link's frame, along a chain of unrotated joints."""
    parents = {child(j, "child").get("link", ""): j for j in robot.findall("joint")}
    position = [0.0, 0.0, 0.0]
    while name in parents:
        xyz, rpy = origin(parents[name])
        assert rpy == [0.0, 0.0, 0.0], f"joint {parents[name].get('name')} is rotated: {rpy}"
        position = [a + b for a, b in zip(position, xyz, strict=True)]
        name = child(parents[name], "parent").get("link", "")
    return position


# ---------------------------------------------------------------- URDF structure checks


def check_tree(robot: ET.Element) -> str:
    """Assert the links and joints form one tree (no dangling names, no link with two
    parents, one root, everything reachable from it) and return the root link's name."""
    links = link_names(robot)
    assert len(links) == len(set(links)), f"duplicate link names in {links}"
    parent_joint: dict[str, str] = {}
    children: dict[str, list[str]] = {name: [] for name in links}
    for j in robot.findall("joint"):
        jname = j.get("name", "")
        parent = child(j, "parent").get("link", "")
        kid = child(j, "child").get("link", "")
        assert parent in children, f"joint {jname!r}: parent {parent!r} is not a link"
        assert kid in children, f"joint {jname!r}: child {kid!r} is not a link"
        assert kid not in parent_joint, (
            f"link {kid!r} is the child of both {parent_joint[kid]!r} and {jname!r}"
        )
        parent_joint[kid] = jname
        children[parent].append(kid)
    roots = [name for name in links if name not in parent_joint]
    assert len(roots) == 1, f"expected a single root link, found {roots}"
    reached, frontier = {roots[0]}, [roots[0]]
    while frontier:
        for kid in children[frontier.pop()]:
            assert kid not in reached, f"link {kid!r} is reached twice (a cycle)"
            reached.add(kid)
            frontier.append(kid)
    assert reached == set(links), f"links not connected to {roots[0]!r}: {set(links) - reached}"
    return roots[0]


def check_inertias(robot: ET.Element) -> None:
    """Assert every link with a body has a mass and a physically possible inertia tensor:
    positive definite (Sylvester's criterion) and principal moments obeying the triangle
    inequality. Links without geometry (pure frames) may have no inertial."""
    for lk in robot.findall("link"):
        name = lk.get("name")
        inertial = lk.find("inertial")
        if inertial is None:
            assert lk.find("visual") is None and lk.find("collision") is None, (
                f"link {name!r} has geometry but no <inertial>"
            )
            continue
        mass = attr(inertial, "mass", "value")
        assert mass > 0, f"link {name!r}: mass {mass}"
        i = {k: float(v) for k, v in child(inertial, "inertia").attrib.items()}
        ixx, iyy, izz, ixy, ixz, iyz = (i[k] for k in ("ixx", "iyy", "izz", "ixy", "ixz", "iyz"))
        assert min(ixx, iyy, izz) > 0, f"link {name!r}: moments {ixx}, {iyy}, {izz}"
        eps = 1e-12
        assert ixx + iyy >= izz - eps and iyy + izz >= ixx - eps and ixx + izz >= iyy - eps, (
            f"link {name!r}: moments {ixx}, {iyy}, {izz} break the triangle inequality"
        )
        minor2 = ixx * iyy - ixy * ixy
        det = (
            ixx * (iyy * izz - iyz * iyz)
            - ixy * (ixy * izz - iyz * ixz)
            + ixz * (ixy * iyz - iyy * ixz)
        )
        assert minor2 > 0 and det > 0, f"link {name!r}: inertia tensor not positive definite"


def check_gazebo_references(robot: ET.Element) -> None:
    """Assert every <gazebo reference=...> block names an existing link."""
    links = set(link_names(robot))
    for gazebo in robot.findall("gazebo"):
        ref = gazebo.get("reference")
        assert ref is None or ref in links, f"<gazebo reference={ref!r}> names no link"


# ---------------------------------------------------------------- jtbot


@pytest.fixture(scope="module")
def jtbot() -> ET.Element:
    """jtbot's URDF as plain `xacro jtbot.urdf.xacro` produces it."""
    return process(JTBOT_XACRO)


@pytest.fixture(scope="module")
def jtbot_props() -> dict[str, str]:
    """jtbot's xacro properties, read from the sources (not from the processed output)."""
    return xacro_properties(*sorted((JTBOT / "urdf").glob("*.xacro")))


def test_jtbot_package_layout() -> None:
    """The package folder is its share directory: urdf/, world/, rviz/ directly below it."""
    for sub in ("urdf/jtbot.urdf.xacro", "world/jt.world", "rviz/jtbot.rviz", "CMakeLists.txt"):
        assert (JTBOT / sub).is_file(), sub
    pkg = ET.parse(JTBOT / "package.xml").getroot()
    assert pkg.get("format") == "3"
    assert text(pkg, "name") == "jtbot_description"
    deps = {(e.text or "").strip() for e in pkg.findall("exec_depend")}
    wanted = {"xacro", "robot_state_publisher", "gazebo_ros", "rviz2", "joint_state_publisher"}
    assert wanted <= deps, wanted - deps
    cmake = (JTBOT / "CMakeLists.txt").read_text()
    assert "project(jtbot_description" in cmake
    assert re.search(r"foreach\(dir urdf world rviz launch config\)", cmake)


def test_jtbot_xacro_has_no_find_and_includes_relative_files() -> None:
    """Plain xacro must do: no $(find) anywhere, and includes are relative paths that exist."""
    for path in (JTBOT / "urdf").glob("*.xacro"):
        source = path.read_text()
        assert "$(find" not in source, f"{path.name} uses $(find ...)"
        for inc in ET.parse(path).getroot().iter(f"{XACRO_NS}include"):
            filename = inc.get("filename", "")
            assert not os.path.isabs(filename), f"{path.name}: absolute include {filename!r}"
            assert (path.parent / filename).is_file(), f"{path.name}: missing {filename!r}"


def test_jtbot_is_one_tree_with_the_seed_parts(jtbot: ET.Element) -> None:
    assert jtbot.get("name") == "jtbot"
    assert check_tree(jtbot) == "base_footprint"
    assert child(joint(jtbot, "base_joint"), "child").get("link") == "base_link"
    parts = {"base_link", "left_wheel_link", "right_wheel_link", "caster_link", "imu_link"}
    parts |= {"laser", "camera_link", "camera_depth_frame"}
    assert parts <= set(link_names(jtbot)), parts - set(link_names(jtbot))
    types = {j.get("name"): j.get("type") for j in jtbot.findall("joint")}
    assert types["left_wheel_joint"] == types["right_wheel_joint"] == "continuous"
    assert [n for n, t in types.items() if t == "continuous"] == [
        "left_wheel_joint",
        "right_wheel_joint",
    ]
    assert types["caster_joint"] == "fixed"
    # camera_depth_frame is the optical frame: z forward (parent x), x right (parent -y).
    _, rpy = origin(joint(jtbot, "camera_depth_joint"))
    rot = rotation(rpy)
    assert [row[2] for row in rot] == pytest.approx([1, 0, 0], abs=1e-9)
    assert [row[0] for row in rot] == pytest.approx([0, -1, 0], abs=1e-9)


def test_jtbot_inertias_are_physical_and_follow_the_formulas(
    jtbot: ET.Element, jtbot_props: dict[str, str]
) -> None:
    check_inertias(jtbot)
    m, r = literal(jtbot_props, "wheel_mass"), literal(jtbot_props, "wheel_radius")
    h = literal(jtbot_props, "wheel_width")
    wheel = child(link(jtbot, "left_wheel_link"), "inertial/inertia").attrib
    assert float(wheel["izz"]) == pytest.approx(m * r * r / 2)
    assert float(wheel["ixx"]) == pytest.approx(m * (3 * r * r + h * h) / 12)
    m = literal(jtbot_props, "base_mass")
    x, y = literal(jtbot_props, "base_length"), literal(jtbot_props, "base_width")
    z = literal(jtbot_props, "base_height")
    base = child(link(jtbot, "base_link"), "inertial/inertia").attrib
    assert float(base["ixx"]) == pytest.approx(m * (y * y + z * z) / 12)
    assert float(base["izz"]) == pytest.approx(m * (x * x + y * y) / 12)
    caster = link(jtbot, "caster_link")
    rc = attr(caster, "collision/geometry/sphere", "radius")
    m = literal(jtbot_props, "caster_mass")
    iyy = attr(caster, "inertial/inertia", "iyy")
    assert iyy == pytest.approx(0.4 * m * rc * rc)


def test_jtbot_stands_on_its_wheels_and_caster(jtbot: ET.Element) -> None:
    """The wheels and the caster reach exactly down to base_footprint (the ground)."""
    wheel_z = offset_from_root(jtbot, "left_wheel_link")[2]
    radius = attr(link(jtbot, "left_wheel_link"), "visual/geometry/cylinder", "radius")
    assert wheel_z == pytest.approx(radius)
    caster_z = offset_from_root(jtbot, "caster_link")[2]
    caster_r = attr(link(jtbot, "caster_link"), "visual/geometry/sphere", "radius")
    assert caster_r > 0
    assert caster_z == pytest.approx(caster_r)


def test_jtbot_diff_drive_is_derived_from_the_properties(
    jtbot: ET.Element, jtbot_props: dict[str, str]
) -> None:
    drive = plugin(jtbot, "libgazebo_ros_diff_drive.so")
    base_width, wheel_width = (
        literal(jtbot_props, "base_width"),
        literal(jtbot_props, "wheel_width"),
    )
    wheel_radius = literal(jtbot_props, "wheel_radius")
    separation, diameter = number(drive, "wheel_separation"), number(drive, "wheel_diameter")
    assert separation == pytest.approx(base_width + wheel_width)
    assert diameter == pytest.approx(2 * wheel_radius)
    assert (separation, diameter) == pytest.approx((0.52, 0.155))  # the seed's figures
    # The plugin's figures match the model it drives.
    left, right = text(drive, "left_joint"), text(drive, "right_joint")
    assert (left, right) == ("left_wheel_joint", "right_wheel_joint")
    y_left, y_right = origin(joint(jtbot, left))[0][1], origin(joint(jtbot, right))[0][1]
    assert y_left > 0 > y_right
    assert y_left - y_right == pytest.approx(separation)
    cyl = child(link(jtbot, "left_wheel_link"), "collision/geometry/cylinder")
    assert 2 * attr(cyl, ".", "radius") == pytest.approx(diameter)
    assert number(drive, "max_wheel_torque") == 20
    assert number(drive, "max_wheel_acceleration") == 1.0
    for flag in ("publish_odom", "publish_odom_tf", "publish_wheel_tf"):
        assert text(drive, flag) == "true", flag
    assert text(drive, "odometry_frame") == "odom"
    # The URDF's root, so odom -> base_footprint -> base_link is one tree (base_link has its
    # parent from the state publisher already).
    assert text(drive, "robot_base_frame") == "base_footprint" == check_tree(jtbot)


def test_jtbot_imu(jtbot: ET.Element) -> None:
    ref, imu = sensor(jtbot, "imu")
    assert ref == "imu_link"
    p = plugin(jtbot, "libgazebo_ros_imu_sensor.so")
    assert text(p, "ros/remapping") == "~/out:=imu"
    assert number(imu, "update_rate") == 100
    assert text(imu, "always_on") == "true"
    figures = {
        "angular_velocity": (0.0, 2e-4, 0.0000075, 0.0000008),
        "linear_acceleration": (0.0, 1.7e-2, 0.1, 0.001),
    }
    for quantity, expected in figures.items():
        for axis in "xyz":
            noise = child(imu, f"imu/{quantity}/{axis}/noise")
            assert noise.get("type") == "gaussian"
            got = tuple(number(noise, k) for k in ("mean", "stddev", "bias_mean", "bias_stddev"))
            assert got == pytest.approx(expected), f"{quantity} {axis}"


def test_jtbot_lidar(jtbot: ET.Element) -> None:
    ref, lidar = sensor(jtbot, "ray")
    assert text(lidar, "always_on") == "true"
    assert text(lidar, "visualize") == "false"
    assert number(lidar, "update_rate") == 5
    scan = child(lidar, "ray/scan/horizontal")
    assert number(scan, "samples") == 360
    assert number(scan, "resolution") == 1
    assert (number(scan, "min_angle"), number(scan, "max_angle")) == pytest.approx((0, 6.28))
    rng = child(lidar, "ray/range")
    assert (number(rng, "min"), number(rng, "max")) == pytest.approx((0.12, 3.5))
    assert number(rng, "resolution") == pytest.approx(0.015)
    noise = child(lidar, "ray/noise")
    assert text(noise, "type") == "gaussian"
    assert (number(noise, "mean"), number(noise, "stddev")) == pytest.approx((0.0, 0.01))
    p = child(lidar, "plugin")
    assert p.get("filename") == "libgazebo_ros_ray_sensor.so"
    assert text(p, "ros/remapping") == "~/out:=scan"
    assert text(p, "output_type") == "sensor_msgs/LaserScan"
    # The scan's frame is the link the sensor is mounted on.
    assert text(p, "frame_name") == ref == "laser"


def test_jtbot_depth_camera(jtbot: ET.Element) -> None:
    ref, cam = sensor(jtbot, "depth")
    assert ref == "camera_link"
    assert text(cam, "always_on") == "true"
    assert number(cam, "update_rate") == 30
    assert number(cam, "camera/horizontal_fov") == pytest.approx(1.047198)
    image = child(cam, "camera/image")
    assert (number(image, "width"), number(image, "height")) == (640, 480)
    assert text(image, "format") == "R8G8B8"
    clip = child(cam, "camera/clip")
    assert (number(clip, "near"), number(clip, "far")) == pytest.approx((0.05, 3))
    p = child(cam, "plugin")
    assert p.get("filename") == "libgazebo_ros_camera.so"
    assert number(p, "baseline") == pytest.approx(0.2)
    assert text(p, "frame_name") == "camera_depth_frame"
    assert "camera_depth_frame" in link_names(jtbot)
    assert (number(p, "min_depth"), number(p, "max_depth")) == pytest.approx((0.5, 3.0))
    cutoffs = (number(p, "pointCloudCutoff"), number(p, "pointCloudCutoffMax"))
    assert cutoffs == pytest.approx((0.5, 3.0))
    for k in ("distortionK1", "distortionK2", "distortionK3", "distortionT1", "distortionT2"):
        assert number(p, k) == 0, k


def test_jtbot_gazebo_blocks_name_links_and_colour_the_parts(jtbot: ET.Element) -> None:
    check_gazebo_references(jtbot)
    colours = {g.get("reference"): text(g, "material") for g in jtbot.findall("gazebo[material]")}
    for part in ("base_link", "left_wheel_link", "right_wheel_link", "caster_link"):
        assert colours.get(part, "").startswith("Gazebo/"), part
    # RViz colours: every visual's material is defined at top level.
    defined = {m.get("name") for m in jtbot.findall("material")}
    used = {m.get("name") for m in jtbot.iter("material") if m.get("name")}
    assert used <= defined, used - defined


def test_jtbot_without_gazebo_arg_is_links_and_joints_only() -> None:
    robot = process(JTBOT_XACRO, gazebo="false")
    assert robot.findall("gazebo") == []
    assert check_tree(robot) == "base_footprint"


def test_jtbot_includes_resolve_from_any_working_directory(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, jtbot: ET.Element
) -> None:
    monkeypatch.chdir(tmp_path)
    relative = os.path.relpath(JTBOT_XACRO, tmp_path)
    for path in (str(JTBOT_XACRO), relative):
        assert canonical(process(path)) == canonical(jtbot), path


def test_plain_xacro_command_line_processes_jtbot(jtbot: ET.Element) -> None:
    """`xacro jtbot.urdf.xacro` in the urdf folder, exactly as the xacro's header says."""
    exe = Path(sys.executable).parent / "xacro"
    command = [str(exe)] if exe.exists() else [shutil.which("xacro") or "xacro"]
    if not Path(command[0]).exists() and shutil.which(command[0]) is None:
        pytest.skip("no xacro command line installed next to this python")
    done = subprocess.run(
        [*command, "jtbot.urdf.xacro"],
        cwd=JTBOT / "urdf",
        capture_output=True,
        text=True,
        timeout=30,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    assert canonical(ET.fromstring(done.stdout)) == canonical(jtbot)


def with_property(source: str, name: str, value: str) -> str:
    """The xacro source with one literal property changed (exactly one declaration)."""
    pattern = re.compile(rf'(<xacro:property\s+name="{re.escape(name)}"\s+value=")[^"]*(")')
    changed, count = pattern.subn(rf"\g<1>{value}\g<2>", source)
    assert count == 1, f"property {name!r} declared {count} times"
    return changed


def test_changing_a_constant_gives_a_different_robot(tmp_path: Path) -> None:
    """The seed's point: edit base_width and wheel_radius, and every derived figure follows."""
    copy = tmp_path / "urdf"
    shutil.copytree(JTBOT / "urdf", copy)
    main = copy / "jtbot.urdf.xacro"
    source = with_property(main.read_text(), "base_width", "0.40")
    main.write_text(with_property(source, "wheel_radius", "0.1"))
    robot = process(main)
    drive = plugin(robot, "libgazebo_ros_diff_drive.so")
    wheel_width = literal(xacro_properties(main), "wheel_width")
    assert number(drive, "wheel_separation") == pytest.approx(0.40 + wheel_width)
    assert number(drive, "wheel_diameter") == pytest.approx(0.2)
    assert origin(joint(robot, "left_wheel_joint"))[0][1] == pytest.approx((0.40 + wheel_width) / 2)
    # Still standing on the ground, still a valid physical tree.
    assert offset_from_root(robot, "left_wheel_link")[2] == pytest.approx(0.1)
    caster_r = attr(link(robot, "caster_link"), "visual/geometry/sphere", "radius")
    assert offset_from_root(robot, "caster_link")[2] == pytest.approx(caster_r)
    check_tree(robot)
    check_inertias(robot)


# ---------------------------------------------------------------- jtbot's world


@dataclass(frozen=True)
class Obstacle:
    """A static upright box or cylinder of the world, as a lidar in a plane sees it."""

    name: str
    x: float
    y: float
    yaw: float
    z_low: float
    z_high: float
    half_x: float = 0.0  # box half sizes
    half_y: float = 0.0
    radius: float = 0.0  # cylinder radius (0 for a box)

    def hit(self, ox: float, oy: float, dx: float, dy: float) -> float | None:
        """Distance along the unit ray (ox, oy) + t (dx, dy) to this obstacle, if it is hit."""
        if self.radius > 0:
            return _ray_circle(ox - self.x, oy - self.y, dx, dy, self.radius)
        c, s = math.cos(-self.yaw), math.sin(-self.yaw)
        lx, ly = c * (ox - self.x) - s * (oy - self.y), s * (ox - self.x) + c * (oy - self.y)
        return _ray_box(lx, ly, c * dx - s * dy, s * dx + c * dy, self.half_x, self.half_y)


def _ray_circle(ox: float, oy: float, dx: float, dy: float, r: float) -> float | None:
    b = ox * dx + oy * dy
    disc = b * b - (ox * ox + oy * oy - r * r)
    if disc < 0:
        return None
    t = -b - math.sqrt(disc)
    return t if t > 0 else None


def _ray_box(ox: float, oy: float, dx: float, dy: float, hx: float, hy: float) -> float | None:
    t_near, t_far = -math.inf, math.inf
    for o, d, h in ((ox, dx, hx), (oy, dy, hy)):
        if abs(d) < 1e-12:
            if abs(o) > h:
                return None
            continue
        t1, t2 = sorted(((-h - o) / d, (h - o) / d))
        t_near, t_far = max(t_near, t1), min(t_far, t2)
    return t_near if t_near <= t_far and t_near > 0 else None


def _pose(elem: ET.Element | None) -> tuple[float, float, float, float]:
    """x, y, z, yaw of an SDF element's <pose>; obstacles must stand upright."""
    if elem is None or elem.find("pose") is None:
        return 0.0, 0.0, 0.0, 0.0
    x, y, z, roll, pitch, yaw = floats(text(elem, "pose"))
    assert roll == pitch == 0, f"{elem.get('name')}: tilted pose"
    return x, y, z, yaw


def _compose(
    a: tuple[float, float, float, float], b: tuple[float, float, float, float]
) -> tuple[float, float, float, float]:
    c, s = math.cos(a[3]), math.sin(a[3])
    return a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], a[2] + b[2], a[3] + b[3]


def world_obstacles(world: ET.Element) -> list[Obstacle]:
    """The world's static box/cylinder models (ground planes and the like are not obstacles)."""
    found = []
    for model in world.findall("model"):
        if text(model, "static") != "true":
            continue
        lk = child(model, "link")
        col = child(lk, "collision")
        x, y, z, yaw = _compose(_compose(_pose(model), _pose(lk)), _pose(col))
        box, cyl = col.find("geometry/box"), col.find("geometry/cylinder")
        visual = child(lk, "visual/geometry")
        name = model.get("name", "")
        if box is not None:
            sx, sy, sz = floats(text(box, "size"))
            assert visual.find("box") is not None, f"{name}: visual does not match"
            found.append(Obstacle(name, x, y, yaw, z - sz / 2, z + sz / 2, sx / 2, sy / 2))
        elif cyl is not None:
            r, length = number(cyl, "radius"), number(cyl, "length")
            assert visual.find("cylinder") is not None, f"{name}: visual does not match"
            found.append(Obstacle(name, x, y, yaw, z - length / 2, z + length / 2, radius=r))
    return found


@dataclass(frozen=True)
class Lidar:
    """The lidar as jtbot's URDF configures it: mount offset, beams and range."""

    x: float
    z: float
    angles: list[float]
    range_min: float
    range_max: float

    def scan(self, obstacles: list[Obstacle], robot_x: float) -> list[tuple[float, str] | None]:
        """One sweep from a robot at (robot_x, 0) facing +x: nearest hit per beam, if any."""
        ox = robot_x + self.x
        seen = [o for o in obstacles if o.z_low <= self.z <= o.z_high]
        beams: list[tuple[float, str] | None] = []
        for angle in self.angles:
            dx, dy = math.cos(angle), math.sin(angle)
            hits = [(t, o.name) for o in seen if (t := o.hit(ox, 0.0, dx, dy)) is not None]
            near = min(hits, default=None)
            ok = near is not None and self.range_min <= near[0] <= self.range_max
            beams.append(near if ok else None)
        return beams


def jtbot_lidar(robot: ET.Element) -> Lidar:
    ref, ray = sensor(robot, "ray")
    x, _, z = offset_from_root(robot, ref)
    scan = child(ray, "ray/scan/horizontal")
    n, lo, hi = int(number(scan, "samples")), number(scan, "min_angle"), number(scan, "max_angle")
    angles = [lo + i * (hi - lo) / (n - 1) for i in range(n)]
    rng = child(ray, "ray/range")
    return Lidar(x, z, angles, number(rng, "min"), number(rng, "max"))


@pytest.fixture(scope="module")
def world() -> ET.Element:
    root = ET.parse(JTBOT / "world" / "jt.world").getroot()
    assert root.tag == "sdf" and root.get("version") == "1.6"
    return child(root, "world")


def test_world_has_ground_sun_and_static_obstacles(world: ET.Element) -> None:
    assert world.get("name")
    assert world.find("light[@type='directional']") is not None
    planes = [m for m in world.findall("model") if m.find("link/collision/geometry/plane")]
    assert len(planes) == 1
    obstacles = world_obstacles(world)
    assert len(obstacles) >= 3, [o.name for o in obstacles]
    names = [o.name for o in obstacles]
    assert len(names) == len(set(names)), names


def test_world_is_what_the_lidar_sees(jtbot: ET.Element, world: ET.Element) -> None:
    """From the spawn point the lidar sees several obstacles; 1 m forward it sees more walls
    and the obstacle ahead 1 m nearer."""
    lidar, obstacles = jtbot_lidar(jtbot), world_obstacles(world)
    start, moved = lidar.scan(obstacles, 0.0), lidar.scan(obstacles, 1.0)
    seen_start = {b[1] for b in start if b}
    seen_moved = {b[1] for b in moved if b}
    assert len(seen_start) >= 3, seen_start
    assert seen_moved != seen_start, seen_moved
    ahead_start, ahead_moved = start[0], moved[0]
    assert ahead_start is not None and ahead_moved is not None
    assert ahead_start[0] - ahead_moved[0] == pytest.approx(1.0)
    # Nothing stands in the robot's own footprint at the spawn point.
    assert min(b[0] for b in start if b) > 0.5


# ---------------------------------------------------------------- jtbot's RViz config


def rviz_displays(path: Path) -> tuple[dict[str, Any], dict[str, dict[str, Any]]]:
    """The global options and the displays by class of an rviz config (it must be YAML)."""
    config = yaml.safe_load(path.read_text())
    manager = config["Visualization Manager"]
    displays = {str(d["Class"]).split("/")[-1]: d for d in manager["Displays"]}
    return manager["Global Options"], displays


def test_jtbot_rviz_config() -> None:
    options, displays = rviz_displays(JTBOT / "rviz" / "jtbot.rviz")
    assert options["Fixed Frame"] == "odom"
    assert {"Grid", "RobotModel", "LaserScan", "Odometry", "TF"} <= set(displays)
    assert all(str(d["Class"]).startswith("rviz_default_plugins/") for d in displays.values())
    model = displays["RobotModel"]
    assert model["Description Source"] == "Topic"
    assert model["Description Topic"]["Value"] == "/robot_description"
    assert displays["LaserScan"]["Topic"]["Value"] == "/scan"
    assert displays["Odometry"]["Topic"]["Value"] == "/odom"


# ---------------------------------------------------------------- smartcar


@pytest.fixture
def ament_prefix(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    """A throw-away ament prefix holding smartcar_description, so $(find) resolves to it."""
    prefix = tmp_path / "prefix"
    marker = prefix / "share" / "ament_index" / "resource_index" / "packages"
    marker.mkdir(parents=True)
    (marker / "smartcar_description").touch()
    (prefix / "share" / "smartcar_description").symlink_to(SMARTCAR, target_is_directory=True)
    monkeypatch.setenv("AMENT_PREFIX_PATH", str(prefix))
    yield prefix


@pytest.fixture
def smartcar(ament_prefix: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> ET.Element:
    monkeypatch.chdir(tmp_path)  # includes must come from $(find), not the working directory
    return process(SMARTCAR_XACRO)


@pytest.fixture(scope="module")
def smartcar_props() -> dict[str, str]:
    return xacro_properties(*sorted((SMARTCAR / "urdf").glob("*.xacro")))


def test_smartcar_package_layout() -> None:
    pkg = ET.parse(SMARTCAR / "package.xml").getroot()
    assert pkg.get("format") == "2"
    assert text(pkg, "name") == "smartcar_description"
    for sub in ("urdf/smartcar_body.urdf.xacro", "urdf/gazebo.urdf.xacro", "urdf.rviz"):
        assert (SMARTCAR / sub).is_file(), sub
    # The ROS 1 habit the seed has: includes go through the package lookup.
    includes = [
        inc.get("filename", "")
        for inc in ET.parse(SMARTCAR_XACRO).getroot().iter(f"{XACRO_NS}include")
    ]
    assert includes == [
        "$(find smartcar_description)/urdf/smartcar_body.urdf.xacro",
        "$(find smartcar_description)/urdf/gazebo.urdf.xacro",
    ]


@requires_ament_index
def test_smartcar_without_a_package_lookup_fails_naming_the_package(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("AMENT_PREFIX_PATH", str(tmp_path))
    with pytest.raises(xacro.XacroException, match="smartcar_description"):
        process(SMARTCAR_XACRO)


@requires_ament_index
def test_smartcar_is_the_seed_car(smartcar: ET.Element) -> None:
    assert smartcar.get("name") == "smartcar"
    assert check_tree(smartcar) == "base_link"
    check_inertias(smartcar)
    check_gazebo_references(smartcar)
    base = link(smartcar, "base_link")
    assert floats(child(base, "visual/geometry/box").get("size")) == [0.25, 0.16, 0.05]
    assert origin(child(base, "visual"))[0] == [0, 0, 0.055]
    wheels = [j for j in smartcar.findall("joint") if j.get("type") == "continuous"]
    assert len(wheels) == 4
    positions = set()
    for j in wheels:
        assert floats(child(j, "axis").get("xyz")) == [0, 0, 1]
        assert child(j, "parent").get("link") == "base_link"
        xyz, rpy = origin(j)
        assert rpy == [0, 1.57075, 1.57075]
        positions.add(tuple(xyz))
        # The joint's z axis (the axle) lies along the base's y axis: the wheels roll along x.
        axle = [row[2] for row in rotation(rpy)]
        assert axle == pytest.approx([0, 1, 0], abs=1e-4)
        wheel = link(smartcar, child(j, "child").get("link", ""))
        cyl = child(wheel, "visual/geometry/cylinder")
        assert (attr(cyl, ".", "radius"), attr(cyl, ".", "length")) == (0.025, 0.02)
        assert origin(child(wheel, "visual")) == ([0, 0, 0], [0, 0, 0])
    assert positions == {(x, y, 0.025) for x in (0.08, -0.08) for y in (0.08, -0.08)}
    head = joint(smartcar, "tobox")
    assert head.get("type") == "fixed"
    assert origin(head)[0] == [0.08, 0, 0.08]
    assert child(head, "child").get("link") == "head"
    assert floats(child(link(smartcar, "head"), "visual/geometry/box").get("size")) == [
        0.02,
        0.03,
        0.03,
    ]
    colours = {m.get("name"): m.find("color") for m in smartcar.findall("material")}
    assert set(colours) == {"blue", "black", "white"}


@requires_ament_index
def test_smartcar_diff_drive_is_derived_from_the_properties(
    smartcar: ET.Element, smartcar_props: dict[str, str]
) -> None:
    drive = plugin(smartcar, "libgazebo_ros_diff_drive.so")
    yoff, radius = literal(smartcar_props, "wheel_yoff"), literal(smartcar_props, "wheel_radius")
    assert number(drive, "wheel_separation") == pytest.approx(2 * yoff) == 0.16
    assert number(drive, "wheel_diameter") == pytest.approx(2 * radius) == 0.05
    lefts = [(j.text or "").strip() for j in drive.findall("left_joint")]
    rights = [(j.text or "").strip() for j in drive.findall("right_joint")]
    assert len(lefts) == len(rights) == number(drive, "num_wheel_pairs") == 2
    for name in lefts:
        assert origin(joint(smartcar, name))[0][1] > 0, name
    for name in rights:
        assert origin(joint(smartcar, name))[0][1] < 0, name
    assert text(drive, "odometry_frame") == "odom"
    assert text(drive, "robot_base_frame") == "base_link"


def test_smartcar_arbotix_config_is_the_seeds() -> None:
    config = yaml.safe_load((SMARTCAR / "config" / "smartcar_arbotix.yaml").read_text())
    assert config == {
        "port": "/dev/ttyUSB0",
        "baud": 115200,
        "rate": 20,
        "sync_write": True,
        "sync_read": True,
        "read_rate": 20,
        "write_rate": 20,
        "controllers": {
            "base_controller": {
                "type": "diff_controller",
                "base_frame_id": "base_link",
                "base_width": 0.26,
                "ticks_meter": 4100,
                "Kp": 12,
                "Kd": 12,
                "Ki": 0,
                "Ko": 50,
                "accel_limit": 1.0,
            }
        },
    }


def test_smartcar_rviz_config() -> None:
    options, displays = rviz_displays(SMARTCAR / "urdf.rviz")
    assert options["Fixed Frame"] == "odom"
    assert {"Grid", "RobotModel", "TF"} <= set(displays)
    assert displays["RobotModel"]["Robot Description"] == "robot_description"
