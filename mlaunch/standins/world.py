"""SDF worlds for the simulator stand-in: the static shapes of a world, seen from above.

Gazebo is never installed here, yet robot stacks need a lidar that sees the world's walls and a
robot that stops at them. This module reads an SDF world (boxes, cylinders, spheres, capsules;
ground planes are skipped), turns every collision shape into a top-down disc or convex polygon
with its height span (shapes.py); raycast.py casts rays against them. It is pure Python and
never imports rclpy.
"""

from __future__ import annotations

import math
import os
import xml.etree.ElementTree as ET
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from xml.parsers import expat

from mlaunch.plan.errors import StandinError

# Re-exported: the simulator, its tests and its callers know these from here.
from mlaunch.standins.raycast import GaussianNoise as GaussianNoise
from mlaunch.standins.raycast import NoiseSampler as NoiseSampler
from mlaunch.standins.raycast import RayCaster as RayCaster
from mlaunch.standins.raycast import ScanGeometry as ScanGeometry
from mlaunch.standins.raycast import clearance as clearance
from mlaunch.standins.raycast import seeded_rng as seeded_rng
from mlaunch.standins.shapes import Disc as Disc
from mlaunch.standins.shapes import Polygon as Polygon
from mlaunch.standins.shapes import Pose3 as Pose3
from mlaunch.standins.shapes import Shape as Shape
from mlaunch.standins.shapes import box_shape as box_shape
from mlaunch.standins.shapes import convex_hull as convex_hull
from mlaunch.standins.shapes import cylinder_shape as cylinder_shape
from mlaunch.standins.shapes import sphere_shape as sphere_shape

# Models that every Gazebo world includes and that never block anything.
_HARMLESS_INCLUDES = ("ground_plane", "sun")
# Environment variables Gazebo classic and gz sim search for worlds and model:// URIs.
RESOURCE_PATH_VARS = (
    "GAZEBO_RESOURCE_PATH",
    "GAZEBO_MODEL_PATH",
    "GZ_SIM_RESOURCE_PATH",
    "IGN_GAZEBO_RESOURCE_PATH",
    "SDF_PATH",
)


class WorldError(StandinError):
    """A world file that cannot be read or understood; ``where`` is ``file:line``."""


# ---------------------------------------------------------------- XML with line numbers


@dataclass
class XmlDoc:
    """A parsed XML document that remembers the line each element started on."""

    root: ET.Element
    filename: str
    lines: dict[ET.Element, int] = field(default_factory=dict)

    def where(self, element: ET.Element) -> str:
        """``file:line`` of ``element`` for error messages."""
        line = self.lines.get(element)
        return f"{self.filename}:{line}" if line else self.filename


def parse_xml(text: str, filename: str) -> XmlDoc:
    """Parse ``text`` keeping element line numbers; malformed XML is a WorldError at its line."""
    # ElementTree's C parser does not expose line numbers, so drive expat ourselves.
    parser = expat.ParserCreate()
    builder = ET.TreeBuilder()
    lines: dict[ET.Element, int] = {}

    def start(tag: str, attrs: dict[str, str]) -> None:
        lines[builder.start(tag, attrs)] = parser.CurrentLineNumber

    parser.StartElementHandler = start
    parser.EndElementHandler = builder.end
    parser.CharacterDataHandler = builder.data
    try:
        parser.Parse(text, True)
    except expat.ExpatError as exc:
        reason = expat.ErrorString(exc.code) if exc.code is not None else str(exc)
        raise WorldError(
            f"malformed XML: {reason} (column {exc.offset + 1})",
            where=f"{filename}:{exc.lineno}",
        ) from None
    return XmlDoc(builder.close(), filename, lines)


# ---------------------------------------------------------------- the world


@dataclass
class World:
    """The static obstacles of a world and the few physics settings the stand-in honours."""

    name: str = "default"
    shapes: list[Shape] = field(default_factory=list)
    gravity: tuple[float, float, float] = (0.0, 0.0, -9.8)
    source: str = "<empty world>"
    warnings: list[str] = field(default_factory=list)

    def summary(self) -> str:
        """One line for the simulator's start-up message."""
        discs = sum(isinstance(s, Disc) for s in self.shapes)
        models = len({s.model for s in self.shapes})
        return (
            f"world {self.name!r} from {self.source}: {len(self.shapes)} shapes "
            f"({len(self.shapes) - discs} polygons, {discs} discs) in {models} models"
        )


def load_world(path: str | os.PathLike[str], environ: Mapping[str, str] | None = None) -> World:
    """Read and parse an SDF world file; every failure is a WorldError naming the file."""
    name = os.fspath(path)
    try:
        text = Path(name).read_text(encoding="utf-8")
    except FileNotFoundError:
        raise WorldError("world file does not exist", where=name) from None
    except (OSError, UnicodeDecodeError) as exc:
        raise WorldError(f"cannot read world file: {exc}", where=name) from None
    return parse_world(text, name, environ)


def parse_world(
    text: str, filename: str = "<string>", environ: Mapping[str, str] | None = None
) -> World:
    """Parse SDF text holding one ``<world>`` into a World of top-down shapes."""
    doc = parse_xml(text, filename)
    if doc.root.tag != "sdf":
        raise WorldError(
            f"root element is <{doc.root.tag}>, expected <sdf>", where=doc.where(doc.root)
        )
    worlds = doc.root.findall("world")
    if not worlds:
        found = [child.tag for child in doc.root]
        raise WorldError(f"<sdf> holds no <world> (found {found!r})", where=doc.where(doc.root))
    element = worlds[0]
    world = World(name=element.get("name", "default"), source=filename)
    reader = _SdfReader(doc, world, environ if environ is not None else os.environ)
    if len(worlds) > 1:
        world.warnings.append(f"{doc.where(worlds[1])}: only the first <world> is simulated")
    gx, gy, gz = reader.vector(element.find("gravity"), 3, world.gravity)
    world.gravity = (gx, gy, gz)
    states = reader.state_poses(element)
    for child in element:
        if child.tag == "model":
            reader.model(child, Pose3(), states, top=True)
        elif child.tag == "include":
            reader.include(child, Pose3(), states)
    return world


@dataclass
class _StatePoses:
    """World-frame poses saved in a world's ``<state>``: they win over the models' own poses."""

    models: dict[str, Pose3] = field(default_factory=dict)
    links: dict[tuple[str, str], Pose3] = field(default_factory=dict)


class _SdfReader:
    """Walks models, links and collisions of one document, composing poses as it goes."""

    def __init__(self, doc: XmlDoc, world: World, environ: Mapping[str, str]):
        self.doc = doc
        self.world = world
        self.environ = environ
        self.depth = 0

    # -- values

    def number(self, element: ET.Element | None, default: float | None = None) -> float:
        """The float in ``element``'s text, or ``default`` when the element is absent."""
        if element is None or element.text is None or not element.text.strip():
            if default is None:
                where = self.doc.where(element) if element is not None else self.doc.filename
                raise WorldError("a number is required here", where=where, what=_tag(element))
            return default
        text = element.text.strip()
        try:
            value = float(text)
        except ValueError:
            raise WorldError(
                f"{text!r} is not a number", where=self.doc.where(element), what=_tag(element)
            ) from None
        if not math.isfinite(value):
            raise WorldError(
                f"{text!r} is not a finite number",
                where=self.doc.where(element),
                what=_tag(element),
            )
        return value

    def vector(
        self, element: ET.Element | None, count: int, default: tuple[float, ...]
    ) -> tuple[float, ...]:
        """``count`` whitespace-separated floats from ``element`` (or ``default``)."""
        text = "" if element is None else (element.text or "").strip()
        if element is None or not text:
            return default
        parts = text.split()
        try:
            values = tuple(float(p) for p in parts)
        except ValueError:
            values = ()
        if len(values) != count or not all(math.isfinite(v) for v in values):
            raise WorldError(
                f"{text!r} is not {count} numbers",
                where=self.doc.where(element),
                what=_tag(element),
            )
        return values

    def pose(self, holder: ET.Element) -> Pose3:
        """The ``<pose>`` child of ``holder`` (identity when absent); degrees honoured."""
        element = holder.find("pose")
        if element is None or not (element.text or "").strip():
            return Pose3()
        if element.get("relative_to"):
            self.warn(
                element,
                f"pose relative_to={element.get('relative_to')!r} is taken relative to the parent",
            )
        values = self.vector(element, 6, (0.0,) * 6)
        x, y, z, roll, pitch, yaw = values
        if element.get("degrees", "false").strip().lower() in ("true", "1"):
            roll, pitch, yaw = (math.radians(v) for v in (roll, pitch, yaw))
        return Pose3.from_xyz_rpy(x, y, z, roll, pitch, yaw)

    def warn(self, element: ET.Element, message: str) -> None:
        self.world.warnings.append(f"{self.doc.where(element)}: {message}")

    # -- structure

    def state_poses(self, world: ET.Element) -> _StatePoses:
        """Model and link poses from ``<state>`` (what Gazebo saves with "Save World As")."""
        poses = _StatePoses()
        for state in world.findall("state"):
            for model in state.findall("model"):
                name = model.get("name", "")
                if model.find("pose") is not None:
                    poses.models[name] = self.pose(model)
                for link in model.findall("link"):
                    if link.find("pose") is not None:
                        poses.links[(name, link.get("name", ""))] = self.pose(link)
        return poses

    def model(
        self,
        element: ET.Element,
        parent: Pose3,
        states: _StatePoses,
        top: bool = False,
        name: str | None = None,
    ) -> None:
        """Add every collision shape of ``element`` (a ``<model>``) posed under ``parent``."""
        model_name = name or element.get("name") or ""
        pose = parent.compose(self.pose(element))
        if top and model_name in states.models:
            pose = states.models[model_name]
        for link in element.findall("link"):
            link_pose = pose.compose(self.pose(link))
            key = (model_name, link.get("name") or "")
            if top and key in states.links:
                link_pose = states.links[key]
            for collision in link.findall("collision"):
                self.collision(model_name, collision, link_pose.compose(self.pose(collision)))
        for nested in element.findall("model"):
            self.model(nested, pose, states, name=f"{model_name}::{nested.get('name', '')}")
        for include in element.findall("include"):
            self.include(include, pose, states)

    def collision(self, model: str, element: ET.Element, pose: Pose3) -> None:
        """Turn one ``<collision>``'s geometry into a shape (or skip it, saying why)."""
        geometry = element.find("geometry")
        kinds = [] if geometry is None else list(geometry)
        if not kinds:
            raise WorldError(
                "<collision> has no geometry",
                where=self.doc.where(element),
                what=f"model {model!r}",
            )
        shape = kinds[0]
        kind = shape.tag
        if kind == "box":
            size = self.vector(shape.find("size"), 3, (1.0, 1.0, 1.0))
            self.positive(shape, size)
            self.world.shapes.append(box_shape(model, pose, size))
        elif kind in ("cylinder", "capsule"):
            radius = self.number(shape.find("radius"), 1.0 if kind == "cylinder" else 0.5)
            length = self.number(shape.find("length"), 1.0)
            self.positive(shape, (radius, length))
            if kind == "capsule":  # the hemispherical caps lengthen it
                length += 2 * radius
            self.world.shapes.append(cylinder_shape(model, pose, radius, length))
        elif kind == "sphere":
            radius = self.number(shape.find("radius"), 1.0)
            self.positive(shape, (radius,))
            self.world.shapes.append(sphere_shape(model, pose, radius))
        elif kind in ("plane", "empty"):
            return  # the ground: rays are horizontal and the robot drives on it
        else:
            self.warn(
                shape,
                f"model {model!r}: <{kind}> geometry is not simulated "
                "(only box, cylinder, sphere, capsule)",
            )

    def positive(self, element: ET.Element, values: Sequence[float]) -> None:
        if any(v <= 0 for v in values):
            raise WorldError(
                f"sizes must be positive, got {tuple(values)!r}",
                where=self.doc.where(element),
                what=f"<{element.tag}>",
            )

    def include(self, element: ET.Element, parent: Pose3, states: _StatePoses) -> None:
        """Resolve ``<include><uri>model://NAME</uri>`` through the Gazebo model paths."""
        uri = (element.findtext("uri") or "").strip()
        model_name = uri.removeprefix("model://").strip("/").split("/")[-1]
        # Fuel names them "Ground Plane" and "Sun" (https://fuel.gazebosim.org/.../models/Sun).
        if model_name.lower().replace(" ", "_") in _HARMLESS_INCLUDES:
            return
        if uri.startswith(("http://", "https://")):
            self.warn(element, f"<include> {uri!r}: the stand-in downloads no Fuel models; skipped")
            return
        found = find_model_sdf(uri, self.environ)
        if found is None:
            self.warn(
                element, f"<include> {uri!r} not found in ${'/$'.join(RESOURCE_PATH_VARS)}; skipped"
            )
            return
        if self.depth > 8:
            raise WorldError(
                f"<include> {uri!r} nests too deeply (a cycle?)", where=self.doc.where(element)
            )
        try:
            text = found.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as exc:
            raise WorldError(
                f"cannot read included model {found}: {exc}", where=self.doc.where(element)
            ) from None
        included = parse_xml(text, str(found))
        model = included.root.find("model")
        if model is None:
            self.warn(element, f"<include> {uri!r}: {found} holds no <model>; skipped")
            return
        name = element.findtext("name") or model.get("name", model_name)
        pose = parent.compose(self.pose(element)) if element.find("pose") is not None else parent
        if name in states.models:
            pose = states.models[name]
        sub = _SdfReader(included, self.world, self.environ)
        sub.depth = self.depth + 1
        # The include's pose replaces the model's own pose, as in SDF.
        sub.model(_without_pose(model), pose, _StatePoses(), name=name)


def _without_pose(model: ET.Element) -> ET.Element:
    copy = ET.Element(model.tag, model.attrib)
    copy.extend(child for child in model if child.tag != "pose")
    return copy


def _tag(element: ET.Element | None) -> str | None:
    return None if element is None else f"<{element.tag}>"


def find_model_sdf(uri: str, environ: Mapping[str, str]) -> Path | None:
    """The ``model.sdf`` (or ``model.config``'s sdf) a ``model://`` or file URI points at."""
    if uri.startswith("file://"):
        base = [Path(uri.removeprefix("file://"))]
    else:
        rel = uri.removeprefix("model://").strip("/")
        base = [
            Path(d) / rel
            for var in RESOURCE_PATH_VARS
            for d in environ.get(var, "").split(os.pathsep)
            if d
        ]
        base.extend(
            Path(d) / "models" / rel
            for var in RESOURCE_PATH_VARS
            for d in environ.get(var, "").split(os.pathsep)
            if d
        )
    for candidate in base:
        if candidate.is_file():
            return candidate
        for name in ("model.sdf", "model-1_4.sdf", "model-1_5.sdf", "model-1_6.sdf"):
            if (candidate / name).is_file():
                return candidate / name
    return None
