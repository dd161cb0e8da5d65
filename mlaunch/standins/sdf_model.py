"""An SDF robot model as URDF, for the stand-ins that read robots as URDF.

Modern Gazebo bringups spawn SDF models (``ros_gz_sim create -file model.sdf``, as
turtlebot3_gazebo does); the simulator stand-in drives URDF robots with ``<gazebo>`` blocks. The
two say the same things differently: in SDF a link's ``<pose>`` is in the model frame and a
joint only names parent and child, in URDF the joint's origin is the child's pose in the parent.
This module writes one as the other: each joint's origin is ``inverse(parent pose) * child
pose``, visuals and collisions keep their poses in the link frame, the model's ``<plugin>``s
become ``<gazebo>`` plugin blocks and each link's ``<sensor>`` a ``<gazebo reference=LINK>``
block, which the simulator stand-in reads as it reads a URDF's. Pure Python (xml.etree).
"""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field

from mlaunch.plan.errors import StandinError
from mlaunch.standins.urdf import Matrix, Vec3, _matmul, _origin

# SDF joint types -> URDF's; the 2D simulator moves none of the others (ball casters, ...).
JOINT_TYPES = {"revolute": "revolute", "continuous": "continuous", "prismatic": "prismatic"}
GEOMETRIES = ("box", "cylinder", "sphere", "mesh")
UNBOUNDED = 1e16  # SDF's default joint limits: a revolute joint with them turns freely
# Whitespace, <?...?>, <!--...--> and <!...> before the root element, then its name.
_ROOT = re.compile(r"(?:\s+|<\?.*?\?>|<!--.*?-->|<![^>]*>)*<([A-Za-z_][\w.-]*)", re.S)


class SdfError(StandinError, ValueError):
    """An SDF model the stand-ins cannot read: the message names the element and the value."""


@dataclass
class Translation:
    """The URDF text and what could not be carried over, one line each."""

    urdf: str
    notes: list[str] = field(default_factory=list)


def is_sdf(xml: str) -> bool:
    """Whether a model's root element is SDF's (``<sdf>`` or a bare ``<model>``), not URDF's.

    The root is found past the XML declaration, comments and doctype (xacro writes a long
    comment banner first)."""
    match = _ROOT.match(xml)
    return match is not None and match.group(1) in ("sdf", "model")


def sdf_to_urdf(xml: str, source: str = "<model>") -> Translation:
    """The first ``<model>`` of an SDF document written as an equivalent URDF robot."""
    try:
        root = ET.fromstring(xml)
    except ET.ParseError as exc:
        raise SdfError(f"{source}: not well-formed XML: {exc}") from None
    model = root if root.tag == "model" else root.find("model")
    if model is None:
        what = "a world, not a model" if root.find("world") is not None else "no <model>"
        raise SdfError(f"{source}: the SDF holds {what}")
    return _Writer(model, source).write()


class _Writer:
    def __init__(self, model: ET.Element, source: str) -> None:
        self.model = model
        self.name = model.get("name") or "model"
        self.where = f"{source}: model {self.name!r}"
        self.notes: list[str] = []
        self.robot = ET.Element("robot", name=self.name)

    def write(self) -> Translation:
        links = self.model.findall("link")
        if not links:
            raise SdfError(f"{self.where}: has no <link>")
        poses = {self._link_name(link): self._pose(link) for link in links}
        for link in links:
            self._link(link)
        children = self._joints(poses)
        self._attach_loose_links(links, poses, children)
        self._plugins()
        for element in self.model:
            if element.tag in ("model", "include"):
                self.notes.append(f"nested <{element.tag}> in model {self.name!r} is left out")
        ET.indent(self.robot)
        return Translation(ET.tostring(self.robot, encoding="unicode"), self.notes)

    def _link_name(self, link: ET.Element) -> str:
        name = link.get("name")
        if not name:
            raise SdfError(f"{self.where}: a <link> has no name")
        return name

    def _pose(self, element: ET.Element) -> Matrix:
        """An element's ``<pose>`` (x y z roll pitch yaw), in the frame it is relative to."""
        pose = element.find("pose")
        if pose is None:
            return _origin((0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
        frame = pose.get("relative_to", "")
        if frame not in ("", "__model__", self.name):
            self.notes.append(
                f"<pose relative_to={frame!r}> of {element.tag} {element.get('name')!r}"
                " is read in the model frame"
            )
        xyz, rpy = self._numbers(pose, element)
        return _origin(xyz, rpy)

    def _numbers(self, pose: ET.Element, owner: ET.Element) -> tuple[Vec3, Vec3]:
        words = (pose.text or "").split()
        try:
            values = [float(w) for w in words]
        except ValueError:
            values = []
        if len(values) != 6 or not all(math.isfinite(v) for v in values):
            raise SdfError(
                f"{self.where}: <pose> of {owner.tag} {owner.get('name')!r} is {pose.text!r};"
                " expected six numbers: x y z roll pitch yaw"
            )
        return (values[0], values[1], values[2]), (values[3], values[4], values[5])

    def _link(self, link: ET.Element) -> None:
        name = self._link_name(link)
        out = ET.SubElement(self.robot, "link", name=name)
        for role in ("visual", "collision"):
            for shape in link.findall(role):
                self._shape(out, shape, role)
        for sensor in link.findall("sensor"):
            block = ET.SubElement(self.robot, "gazebo", reference=name)
            block.append(sensor)

    def _shape(self, out: ET.Element, shape: ET.Element, role: str) -> None:
        geometry = shape.find("geometry")
        kind = next(
            (g for g in (geometry if geometry is not None else []) if g.tag in GEOMETRIES), None
        )
        if kind is None:
            return  # a plane, a heightmap: nothing the stand-ins draw or collide with on a robot
        element = ET.SubElement(out, role)
        if shape.find("pose") is not None:
            xyz, rpy = self._numbers(shape.find("pose"), shape)  # type: ignore[arg-type]
            ET.SubElement(element, "origin", xyz=_words(xyz), rpy=_words(rpy))
        target = ET.SubElement(ET.SubElement(element, "geometry"), kind.tag)
        if kind.tag == "box":
            target.set("size", (kind.findtext("size") or "1 1 1").strip())
        elif kind.tag in ("cylinder", "sphere"):
            target.set("radius", (kind.findtext("radius") or "0.5").strip())
            if kind.tag == "cylinder":
                target.set("length", (kind.findtext("length") or "1").strip())
        else:
            target.set("filename", (kind.findtext("uri") or "").strip())
            target.set("scale", (kind.findtext("scale") or "1 1 1").strip())

    def _joints(self, poses: dict[str, Matrix]) -> set[str]:
        children: set[str] = set()
        for joint in self.model.findall("joint"):
            name = joint.get("name") or "joint"
            parent = (joint.findtext("parent") or "").strip()
            child = (joint.findtext("child") or "").strip()
            if parent == "world":
                self.notes.append(f"joint {name!r} fixes the model to the world: left out")
                continue
            for end, link in (("parent", parent), ("child", child)):
                if link not in poses:
                    raise SdfError(
                        f"{self.where}: joint {name!r} has <{end}> {link!r}, which is no link"
                        f" of the model (links: {', '.join(sorted(poses))})"
                    )
            children.add(child)
            self._joint(joint, name, parent, child, _relative(poses[parent], poses[child]))
        return children

    def _joint(self, joint: ET.Element, name: str, parent: str, child: str, origin: Matrix) -> None:
        kind = joint.get("type", "fixed")
        limit = joint.find("axis/limit")
        lower = _float(limit, "lower", -UNBOUNDED)
        upper = _float(limit, "upper", UNBOUNDED)
        urdf_type = JOINT_TYPES.get(kind, "fixed")
        if urdf_type == "revolute" and (lower <= -UNBOUNDED or upper >= UNBOUNDED):
            urdf_type = "continuous"
        if kind not in JOINT_TYPES and kind != "fixed":
            self.notes.append(f"joint {name!r} of type {kind!r} is held fixed")
        out = ET.SubElement(self.robot, "joint", name=name, type=urdf_type)
        ET.SubElement(out, "parent", link=parent)
        ET.SubElement(out, "child", link=child)
        xyz, rpy = _decompose(origin)
        ET.SubElement(out, "origin", xyz=_words(xyz), rpy=_words(rpy))
        axis = (joint.findtext("axis/xyz") or "").split()
        if urdf_type != "fixed" and len(axis) == 3:
            ET.SubElement(out, "axis", xyz=" ".join(axis))
        if urdf_type in ("revolute", "prismatic"):
            ET.SubElement(
                out,
                "limit",
                lower=repr(lower),
                upper=repr(upper),
                effort=repr(_float(limit, "effort", 0.0)),
                velocity=repr(_float(limit, "velocity", 0.0)),
            )

    def _attach_loose_links(
        self, links: list[ET.Element], poses: dict[str, Matrix], children: set[str]
    ) -> None:
        """URDF has one root: links no joint holds ride on the first root, as they are posed."""
        roots = [self._link_name(link) for link in links if self._link_name(link) not in children]
        for loose in roots[1:]:
            self.notes.append(f"link {loose!r} is joined to no other link: fixed to {roots[0]!r}")
            out = ET.SubElement(self.robot, "joint", name=f"{loose}_fixed", type="fixed")
            ET.SubElement(out, "parent", link=roots[0])
            ET.SubElement(out, "child", link=loose)
            xyz, rpy = _decompose(_relative(poses[roots[0]], poses[loose]))
            ET.SubElement(out, "origin", xyz=_words(xyz), rpy=_words(rpy))

    def _plugins(self) -> None:
        plugins = self.model.findall("plugin")
        if plugins:
            block = ET.SubElement(self.robot, "gazebo")
            for plugin in plugins:
                block.append(plugin)


def _float(element: ET.Element | None, tag: str, default: float) -> float:
    text = None if element is None else element.findtext(tag)
    try:
        return float(text) if text is not None else default
    except ValueError:
        return default


def _relative(parent: Matrix, child: Matrix) -> Matrix:
    """The child's pose in the parent's frame, both given in one common frame."""
    return _matmul(_inverse(parent), child)


def _inverse(m: Matrix) -> Matrix:
    """The inverse of a rigid transform: transposed rotation, rotated negated translation."""
    rot = [[m[c][r] for c in range(3)] for r in range(3)]
    t = [-sum(rot[r][k] * m[k][3] for k in range(3)) for r in range(3)]
    rows = [(*rot[r], t[r]) for r in range(3)]
    return (*rows, (0.0, 0.0, 0.0, 1.0))


def _decompose(m: Matrix) -> tuple[Vec3, Vec3]:
    """xyz and URDF's fixed-axis roll, pitch, yaw of a rigid transform."""
    pitch = math.asin(max(-1.0, min(1.0, -m[2][0])))
    if abs(m[2][0]) < 1.0 - 1e-12:
        roll = math.atan2(m[2][1], m[2][2])
        yaw = math.atan2(m[1][0], m[0][0])
    else:  # gimbal lock: roll and yaw turn about one axis; put it all in yaw
        roll = 0.0
        yaw = math.atan2(-m[0][1], m[1][1])
    return (m[0][3], m[1][3], m[2][3]), (roll, pitch, yaw)


def _words(values: Vec3) -> str:
    return " ".join(f"{0.0 if abs(v) < 1e-12 else v:.9g}" for v in values)
