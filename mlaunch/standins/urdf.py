"""URDF for the stand-ins: parse and validate robot_description, answer geometry questions.

robot_state_publisher refuses a broken URDF, and the simulator and viewer stand-ins need link poses
and a top-down outline of the robot; this module gives all of them one parser with clear errors.
It is pure Python (xml.etree) and never imports rclpy.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Mapping
from dataclasses import dataclass
from functools import cached_property

from mlaunch.plan.errors import StandinError

JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed", "floating", "planar")
GEOMETRY_KINDS = ("box", "cylinder", "sphere", "mesh")

Vec3 = tuple[float, float, float]
Matrix = tuple[tuple[float, ...], ...]  # 4x4 homogeneous transform, row-major


class UrdfError(StandinError, ValueError):
    """An invalid robot_description; the message names the link/joint and the bad value."""


@dataclass(frozen=True)
class Geometry:
    """One visual or collision shape of a link, in the link frame.

    size is (x, y, z) for a box, (radius, length) for a cylinder, (radius,) for a sphere and the
    scale (sx, sy, sz) for a mesh (whose file is in ``filename``).
    """

    kind: str
    size: tuple[float, ...]
    origin_xyz: Vec3 = (0.0, 0.0, 0.0)
    origin_rpy: Vec3 = (0.0, 0.0, 0.0)
    role: str = "visual"
    filename: str = ""


@dataclass(frozen=True)
class Link:
    """A URDF link: a frame with its visual and collision geometries (document order)."""

    name: str
    geometries: tuple[Geometry, ...] = ()


@dataclass(frozen=True)
class Joint:
    """A URDF joint: the child frame's pose in the parent frame, and how it moves (about axis)."""

    name: str
    type: str
    parent: str
    child: str
    origin_xyz: Vec3 = (0.0, 0.0, 0.0)
    origin_rpy: Vec3 = (0.0, 0.0, 0.0)
    axis: Vec3 = (1.0, 0.0, 0.0)
    lower: float | None = None
    upper: float | None = None


@dataclass(frozen=True)
class Circle:
    """A top-down circle in the root frame (a sphere, or a cylinder standing upright)."""

    link: str
    x: float
    y: float
    radius: float

    def to_json(self) -> dict[str, object]:
        """The shape as plain data for the viewer page."""
        return {"type": "circle", "link": self.link, "x": self.x, "y": self.y, "r": self.radius}


@dataclass(frozen=True)
class Polygon:
    """A top-down convex outline in the root frame (a box, or a lying cylinder such as a wheel)."""

    link: str
    points: tuple[tuple[float, float], ...]

    def to_json(self) -> dict[str, object]:
        """The shape as plain data for the viewer page."""
        return {"type": "polygon", "link": self.link, "points": [list(p) for p in self.points]}


Shape2D = Circle | Polygon


@dataclass(frozen=True)
class Robot:
    """A validated URDF robot: a tree of links joined by joints, rooted at ``root``.

    ``links`` and ``joints`` keep document order; ``gazebo`` holds the top-level <gazebo>
    elements untouched for the simulator stand-in.
    """

    name: str
    links: dict[str, Link]
    joints: dict[str, Joint]
    root: str
    gazebo: tuple[ET.Element, ...] = ()

    @cached_property
    def _parent_joint(self) -> dict[str, str]:
        """child link -> name of the joint that holds it."""
        return {joint.child: joint.name for joint in self.joints.values()}

    def movable_joints(self) -> list[Joint]:
        """The non-fixed joints in document order (those joint_states reports)."""
        return [j for j in self.joints.values() if j.type != "fixed"]

    def chain(self, link: str) -> list[Joint]:
        """The joints from the root down to ``link``, root first."""
        if link not in self.links:
            raise UrdfError(f"unknown link {link!r}; links are: {', '.join(self.links)}")
        joints: list[Joint] = []
        while link != self.root:
            joint = self.joints[self._parent_joint[link]]
            joints.append(joint)
            link = joint.parent
        joints.reverse()
        return joints

    def link_transform(self, link: str, positions: Mapping[str, float] | None = None) -> Matrix:
        """The 4x4 pose of ``link`` in the root frame, with joint ``positions`` (default zero)."""
        positions = positions or {}
        pose = _identity()
        for joint in self.chain(link):
            pose = _matmul(pose, _origin(joint.origin_xyz, joint.origin_rpy))
            pose = _matmul(pose, _motion(joint, positions.get(joint.name, 0.0)))
        return pose

    def link_pose_in_root(
        self, link: str, positions: Mapping[str, float] | None = None
    ) -> tuple[float, float, float, float]:
        """(x, y, z, yaw) of ``link`` in the root frame, composing full rpy origins on the way."""
        m = self.link_transform(link, positions)
        return (m[0][3], m[1][3], m[2][3], math.atan2(m[1][0], m[0][0]))

    def footprint(self) -> list[Shape2D]:
        """Top-down outlines of every link's geometry in the root frame, joints at zero.

        Visual geometry is used where a link has any, else its collision geometry (what rviz
        would draw). Meshes are skipped: their extent is unknown without loading the file.
        """
        shapes: list[Shape2D] = []
        for link in self.links.values():
            visuals = [g for g in link.geometries if g.role == "visual"]
            chosen = visuals or [g for g in link.geometries if g.role == "collision"]
            if not chosen:
                continue
            base = self.link_transform(link.name)
            for geom in chosen:
                shape = _project(
                    link.name, _matmul(base, _origin(geom.origin_xyz, geom.origin_rpy)), geom
                )
                if shape is not None:
                    shapes.append(shape)
        return shapes


# ---------------------------------------------------------------- parsing


def parse_urdf(text: str) -> Robot:
    """Parse and validate a URDF document; raise UrdfError naming the problem.

    Checks what robot_state_publisher (urdfdom + kdl) would refuse: XML syntax, a <robot name>,
    unique link and joint names, known joint types, existing parents and children, no link with
    two parents, exactly one root and no cycles, and well-formed numbers.
    """
    if not text or not text.strip():
        raise UrdfError("robot_description is empty; expected a URDF <robot> document")
    try:
        top = ET.fromstring(text)
    except ET.ParseError as exc:
        raise UrdfError(f"robot_description is not well-formed XML: {exc}") from None
    if top.tag != "robot":
        raise UrdfError(f"URDF root element is <{top.tag}>, expected <robot>")
    name = top.get("name")
    if not name:
        raise UrdfError("<robot> has no name attribute; URDF requires <robot name=...>")
    links = _parse_links(top)
    joints = _parse_joints(top, links)
    parent_joint = _parent_joints(joints)
    root = _find_root(links, parent_joint, joints)
    return Robot(
        name=name,
        links=links,
        joints=joints,
        root=root,
        gazebo=tuple(top.findall("gazebo")),
    )


def _parse_links(top: ET.Element) -> dict[str, Link]:
    links: dict[str, Link] = {}
    for element in top.findall("link"):
        name = element.get("name")
        if not name:
            raise UrdfError("a <link> has no name attribute")
        if name in links:
            raise UrdfError(f"link {name!r} is defined twice")
        geometries = [
            _parse_geometry(name, item, role)
            for role in ("visual", "collision")
            for item in element.findall(role)
        ]
        links[name] = Link(name=name, geometries=tuple(geometries))
    if not links:
        raise UrdfError(f"robot {top.get('name')!r} has no <link>; a URDF needs at least one")
    return links


def _parse_geometry(link: str, element: ET.Element, role: str) -> Geometry:
    where = f"link {link!r} <{role}>"
    xyz, rpy = _parse_origin(where, element.find("origin"))
    holder = element.find("geometry")
    shapes = [] if holder is None else [c for c in holder if c.tag in GEOMETRY_KINDS]
    if len(shapes) != 1:
        found = [] if holder is None else [c.tag for c in holder]
        raise UrdfError(
            f"{where}: <geometry> must hold exactly one of box/cylinder/sphere/mesh, "
            f"found {found!r}"
        )
    shape = shapes[0]
    kind = shape.tag
    if kind == "box":
        size = _vector(where, "box size", shape.get("size"), 3, None)
        _positive(where, "box size", size)
        return Geometry(kind, size, xyz, rpy, role)
    if kind == "cylinder":
        size = (_number(where, "cylinder radius", shape.get("radius")),
                _number(where, "cylinder length", shape.get("length")))  # fmt: skip
        _positive(where, "cylinder radius/length", size)
        return Geometry(kind, size, xyz, rpy, role)
    if kind == "sphere":
        size = (_number(where, "sphere radius", shape.get("radius")),)
        _positive(where, "sphere radius", size)
        return Geometry(kind, size, xyz, rpy, role)
    filename = shape.get("filename")
    if not filename:
        raise UrdfError(f"{where}: <mesh> has no filename attribute")
    scale = _vector(where, "mesh scale", shape.get("scale"), 3, (1.0, 1.0, 1.0))
    return Geometry(kind, scale, xyz, rpy, role, filename=filename)


def _parse_joints(top: ET.Element, links: Mapping[str, Link]) -> dict[str, Joint]:
    joints: dict[str, Joint] = {}
    for element in top.findall("joint"):
        joint = _parse_joint(element, links)
        if joint.name in joints:
            raise UrdfError(f"joint {joint.name!r} is defined twice")
        joints[joint.name] = joint
    return joints


def _parse_joint(element: ET.Element, links: Mapping[str, Link]) -> Joint:
    name = element.get("name")
    if not name:
        raise UrdfError("a <joint> has no name attribute")
    where = f"joint {name!r}"
    kind = element.get("type")
    if kind not in JOINT_TYPES:
        raise UrdfError(f"{where} has type {kind!r}; valid types are: {', '.join(JOINT_TYPES)}")
    parent = _link_ref(where, element, "parent", links)
    child = _link_ref(where, element, "child", links)
    if parent == child:
        raise UrdfError(f"{where}: parent and child are the same link {parent!r}")
    xyz, rpy = _parse_origin(where, element.find("origin"))
    axis_element = element.find("axis")
    axis_text = None if axis_element is None else axis_element.get("xyz")
    axis = _vec3(_vector(where, "axis xyz", axis_text, 3, (1.0, 0.0, 0.0)))
    norm = math.sqrt(sum(c * c for c in axis))
    if kind not in ("fixed", "floating") and norm == 0.0:
        raise UrdfError(f"{where}: axis xyz is {axis_text!r}, a zero vector; give a direction")
    if norm:
        axis = _vec3(tuple(c / norm for c in axis))
    lower, upper = _parse_limit(where, kind, element.find("limit"))
    return Joint(name, kind, parent, child, xyz, rpy, axis, lower, upper)


def _link_ref(where: str, element: ET.Element, tag: str, links: Mapping[str, Link]) -> str:
    ref = element.find(tag)
    value = None if ref is None else ref.get("link")
    if not value:
        raise UrdfError(f"{where} has no <{tag} link=...>")
    if value not in links:
        raise UrdfError(
            f"{where}: {tag} link {value!r} does not exist; links are: {', '.join(links)}"
        )
    return value


def _parse_limit(
    where: str, kind: str, element: ET.Element | None
) -> tuple[float | None, float | None]:
    # urdfdom refuses revolute and prismatic joints without limits; continuous ones may have one
    # (its lower/upper are ignored there).
    if element is None:
        if kind in ("revolute", "prismatic"):
            raise UrdfError(f"{where} is {kind} but has no <limit>; {kind} joints require one")
        return None, None
    if kind not in ("revolute", "prismatic"):
        return None, None
    lower = _number(where, "limit lower", element.get("lower", "0"))
    upper = _number(where, "limit upper", element.get("upper", "0"))
    if lower > upper:
        raise UrdfError(f"{where}: limit lower {lower} is above upper {upper}")
    return lower, upper


def _parse_origin(where: str, element: ET.Element | None) -> tuple[Vec3, Vec3]:
    if element is None:
        return (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
    xyz = _vector(where, "origin xyz", element.get("xyz"), 3, (0.0, 0.0, 0.0))
    rpy = _vector(where, "origin rpy", element.get("rpy"), 3, (0.0, 0.0, 0.0))
    return _vec3(xyz), _vec3(rpy)


def _vec3(values: tuple[float, ...]) -> Vec3:
    return (values[0], values[1], values[2])


def _number(where: str, what: str, text: str | None) -> float:
    if text is None:
        raise UrdfError(f"{where}: {what} is missing")
    try:
        value = float(text)
    except ValueError:
        raise UrdfError(f"{where}: {what} is {text!r}, not a number") from None
    if not math.isfinite(value):
        raise UrdfError(f"{where}: {what} is {text!r}, not a finite number")
    return value


def _vector(
    where: str, what: str, text: str | None, count: int, default: tuple[float, ...] | None
) -> tuple[float, ...]:
    if text is None:
        if default is None:
            raise UrdfError(f"{where}: {what} is missing; expected {count} numbers")
        return default
    parts = text.split()
    if len(parts) != count:
        raise UrdfError(f"{where}: {what} is {text!r}; expected {count} numbers")
    return tuple(_number(where, what, p) for p in parts)


def _positive(where: str, what: str, values: tuple[float, ...]) -> None:
    if any(v <= 0 for v in values):
        raise UrdfError(f"{where}: {what} is {values!r}; sizes must be positive")


def _parent_joints(joints: Mapping[str, Joint]) -> dict[str, str]:
    """child link -> the joint that holds it; a link held by two joints is an error."""
    parent_joint: dict[str, str] = {}
    for joint in joints.values():
        other = parent_joint.get(joint.child)
        if other is not None:
            raise UrdfError(
                f"link {joint.child!r} has two parents: joint {other!r} "
                f"(parent {joints[other].parent!r}) and joint {joint.name!r} "
                f"(parent {joint.parent!r}); a URDF must be a tree"
            )
        parent_joint[joint.child] = joint.name
    return parent_joint


def _find_root(
    links: Mapping[str, Link], parent_joint: Mapping[str, str], joints: Mapping[str, Joint]
) -> str:
    roots = [name for name in links if name not in parent_joint]
    if len(roots) > 1:
        raise UrdfError(
            f"the URDF has {len(roots)} root links {roots!r}; exactly one link may have no parent "
            "(join the others to the tree with a joint)"
        )
    if not roots:
        cycle = _cycle_from(next(iter(links)), parent_joint, joints)
        raise UrdfError(f"every link has a parent, so the joints form a cycle: {cycle}")
    # One root and one parent per link: anything not reachable from the root sits on a cycle.
    reached = {roots[0]}
    children: dict[str, list[str]] = {}
    for joint in joints.values():
        children.setdefault(joint.parent, []).append(joint.child)
    stack = [roots[0]]
    while stack:
        for child in children.get(stack.pop(), []):
            if child not in reached:
                reached.add(child)
                stack.append(child)
    lost = [name for name in links if name not in reached]
    if lost:
        cycle = _cycle_from(lost[0], parent_joint, joints)
        raise UrdfError(f"the joints form a cycle: {cycle}")
    return roots[0]


def _cycle_from(start: str, parent_joint: Mapping[str, str], joints: Mapping[str, Joint]) -> str:
    """Walk parents from ``start`` until a link repeats; describe the loop found."""
    seen: list[str] = []
    link = start
    while link not in seen:
        seen.append(link)
        link = joints[parent_joint[link]].parent
    loop = [*seen[seen.index(link) :], link]
    loop.reverse()
    return " -> ".join(repr(name) for name in loop)


# ---------------------------------------------------------------- kinematics


def joint_transform(joint: Joint, q: float) -> Matrix:
    """The child's 4x4 pose in the parent frame at joint position q (origin, then motion)."""
    return _matmul(_origin(joint.origin_xyz, joint.origin_rpy), _motion(joint, q))


def _identity() -> Matrix:
    return tuple(tuple(1.0 if r == c else 0.0 for c in range(4)) for r in range(4))


def _matmul(a: Matrix, b: Matrix) -> Matrix:
    return tuple(
        tuple(sum(a[r][k] * b[k][c] for k in range(4)) for c in range(4)) for r in range(4)
    )


def _from_rotation(rot: list[list[float]], xyz: Vec3) -> Matrix:
    rows = [[*rot[r], xyz[r]] for r in range(3)]
    return (*(tuple(row) for row in rows), (0.0, 0.0, 0.0, 1.0))


def _origin(xyz: Vec3, rpy: Vec3) -> Matrix:
    """URDF origin: fixed-axis roll, pitch, yaw, i.e. R = Rz(yaw) Ry(pitch) Rx(roll)."""
    roll, pitch, yaw = rpy
    cr, sr = math.cos(roll), math.sin(roll)
    cp, sp = math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    rot = [
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ]
    return _from_rotation(rot, xyz)


def _motion(joint: Joint, q: float) -> Matrix:
    """The joint's own motion by position q, applied after its origin (about/along its axis)."""
    if joint.type in ("revolute", "continuous") and q:
        x, y, z = joint.axis
        c, s, t = math.cos(q), math.sin(q), 1.0 - math.cos(q)
        rot = [  # Rodrigues: rotation by q about the unit axis
            [t * x * x + c, t * x * y - s * z, t * x * z + s * y],
            [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
            [t * x * z - s * y, t * y * z + s * x, t * z * z + c],
        ]
        return _from_rotation(rot, (0.0, 0.0, 0.0))
    if joint.type == "prismatic" and q:
        ax, ay, az = joint.axis
        return _from_rotation([[1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0]], (ax * q, ay * q, az * q))
    return _identity()


def _apply(m: Matrix, p: Vec3) -> tuple[float, float]:
    return (
        m[0][0] * p[0] + m[0][1] * p[1] + m[0][2] * p[2] + m[0][3],
        m[1][0] * p[0] + m[1][1] * p[1] + m[1][2] * p[2] + m[1][3],
    )


def _project(link: str, pose: Matrix, geom: Geometry) -> Shape2D | None:
    """The top-down outline of one primitive posed at ``pose`` (root frame)."""
    if geom.kind == "sphere":
        x, y = _apply(pose, (0.0, 0.0, 0.0))
        return Circle(link, x, y, geom.size[0])
    if geom.kind == "box":
        hx, hy, hz = (s / 2 for s in geom.size)
        corners = [
            (sx * hx, sy * hy, sz * hz) for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)
        ]
        return Polygon(link, _hull([_apply(pose, c) for c in corners]))
    if geom.kind == "cylinder":
        radius, length = geom.size
        if abs(pose[2][2]) > 0.999:  # axis points up: seen from above it is a disc
            x, y = _apply(pose, (0.0, 0.0, 0.0))
            return Circle(link, x, y, radius)
        ring = [
            (radius * math.cos(a), radius * math.sin(a), z)
            for a in (i * math.pi / 8 for i in range(16))
            for z in (-length / 2, length / 2)
        ]
        return Polygon(link, _hull([_apply(pose, p) for p in ring]))
    return None


def _hull(points: list[tuple[float, float]]) -> tuple[tuple[float, float], ...]:
    """Convex hull, counter-clockwise (Andrew's monotone chain); rounded to keep JSON small."""
    pts = sorted({(round(x, 5), round(y, 5)) for x, y in points})
    if len(pts) <= 2:
        return tuple(pts)

    def cross(o: tuple[float, float], a: tuple[float, float], b: tuple[float, float]) -> float:
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower: list[tuple[float, float]] = []
    upper: list[tuple[float, float]] = []
    for p in pts:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= 0:
            lower.pop()
        lower.append(p)
    for p in reversed(pts):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= 0:
            upper.pop()
        upper.append(p)
    return tuple(lower[:-1] + upper[:-1])
