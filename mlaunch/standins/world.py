"""SDF worlds for the simulator stand-in: static shapes seen from above, 2D ray casting, noise.

Gazebo is never installed here, yet robot stacks need a lidar that sees the world's walls and a
robot that stops at them. This module reads an SDF world (boxes, cylinders, spheres, capsules;
ground planes are skipped), turns every collision shape into a top-down disc or convex polygon
with its height span, and casts horizontal rays against them exactly. It is pure Python and
never imports rclpy.
"""

from __future__ import annotations

import math
import os
import random
import xml.etree.ElementTree as ET
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from xml.parsers import expat

from mlaunch.errors import MlaunchError

Point = tuple[float, float]
Rotation = tuple[tuple[float, float, float], ...]  # 3x3, row-major

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


class WorldError(MlaunchError):
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


# ---------------------------------------------------------------- 3D poses


@dataclass(frozen=True)
class Pose3:
    """A rigid transform: rotation matrix and translation (SDF ``<pose>`` or a composition)."""

    rot: Rotation = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
    xyz: tuple[float, float, float] = (0.0, 0.0, 0.0)

    @staticmethod
    def from_xyz_rpy(x: float, y: float, z: float, roll: float, pitch: float, yaw: float) -> Pose3:
        """The SDF/URDF convention: fixed-axis roll, pitch, yaw, R = Rz(yaw) Ry(pitch) Rx(roll)."""
        cr, sr = math.cos(roll), math.sin(roll)
        cp, sp = math.cos(pitch), math.sin(pitch)
        cy, sy = math.cos(yaw), math.sin(yaw)
        rot = (
            (cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr),
            (sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr),
            (-sp, cp * sr, cp * cr),
        )
        return Pose3(rot, (x, y, z))

    def apply(self, p: Sequence[float]) -> tuple[float, float, float]:
        """The point ``p`` (child frame) expressed in the parent frame."""
        r, t = self.rot, self.xyz
        return (
            r[0][0] * p[0] + r[0][1] * p[1] + r[0][2] * p[2] + t[0],
            r[1][0] * p[0] + r[1][1] * p[1] + r[1][2] * p[2] + t[1],
            r[2][0] * p[0] + r[2][1] * p[1] + r[2][2] * p[2] + t[2],
        )

    def compose(self, child: Pose3) -> Pose3:
        """``self * child``: the child's pose expressed in self's parent frame."""
        a, b = self.rot, child.rot
        rot = tuple(
            tuple(sum(a[r][k] * b[k][c] for k in range(3)) for c in range(3)) for r in range(3)
        )
        return Pose3(rot, self.apply(child.xyz))  # type: ignore[arg-type]

    @property
    def yaw(self) -> float:
        """Heading of the x axis seen from above."""
        return math.atan2(self.rot[1][0], self.rot[0][0])


# ---------------------------------------------------------------- shapes


@dataclass(frozen=True)
class Disc:
    """An upright cylinder (or a sphere, or a vertical capsule) seen from above."""

    model: str
    x: float
    y: float
    radius: float
    zmin: float
    zmax: float
    sphere_z: float | None = None  # a sphere's centre height: its cross-section shrinks off-centre

    def radius_at(self, z: float) -> float:
        """Radius of the horizontal cross-section at height ``z`` (0 when it misses)."""
        if z < self.zmin or z > self.zmax:
            return 0.0
        if self.sphere_z is None:
            return self.radius
        return math.sqrt(max(0.0, self.radius**2 - (z - self.sphere_z) ** 2))

    @property
    def bound(self) -> tuple[float, float, float]:
        """Bounding circle (x, y, r) used to skip rays that cannot reach the shape."""
        return (self.x, self.y, self.radius)

    def clearance(self, x: float, y: float) -> float:
        """Distance from (x, y) to the outline; negative inside."""
        return math.hypot(x - self.x, y - self.y) - self.radius


@dataclass(frozen=True)
class Polygon:
    """A convex outline seen from above (a box, a lying cylinder), counter-clockwise."""

    model: str
    points: tuple[Point, ...]
    zmin: float
    zmax: float

    @property
    def bound(self) -> tuple[float, float, float]:
        """Bounding circle (x, y, r) around the vertices' centroid."""
        cx = sum(p[0] for p in self.points) / len(self.points)
        cy = sum(p[1] for p in self.points) / len(self.points)
        return (cx, cy, max(math.hypot(p[0] - cx, p[1] - cy) for p in self.points))

    def edges(self) -> list[tuple[Point, Point]]:
        """Consecutive vertex pairs, closing the loop."""
        pts = self.points
        return [(pts[i], pts[(i + 1) % len(pts)]) for i in range(len(pts))]

    def clearance(self, x: float, y: float) -> float:
        """Distance from (x, y) to the outline; negative (minus the depth) inside."""
        inside = True
        best = math.inf
        for (ax, ay), (bx, by) in self.edges():
            ex, ey = bx - ax, by - ay
            if ex * (y - ay) - ey * (x - ax) < 0:
                inside = False
            length2 = ex * ex + ey * ey
            s = (
                0.0
                if length2 == 0
                else max(0.0, min(1.0, ((x - ax) * ex + (y - ay) * ey) / length2))
            )
            best = min(best, math.hypot(x - ax - s * ex, y - ay - s * ey))
        return -best if inside else best


Shape = Disc | Polygon


def convex_hull(points: Iterable[Point]) -> tuple[Point, ...]:
    """Counter-clockwise convex hull (Andrew's monotone chain)."""
    pts = sorted(set(points))
    if len(pts) <= 2:
        return tuple(pts)

    def cross(o: Point, a: Point, b: Point) -> float:
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower: list[Point] = []
    upper: list[Point] = []
    for p in pts:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= 1e-12:
            lower.pop()
        lower.append(p)
    for p in reversed(pts):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= 1e-12:
            upper.pop()
        upper.append(p)
    return tuple(lower[:-1] + upper[:-1])


def box_shape(model: str, pose: Pose3, size: Sequence[float]) -> Shape:
    """A box of ``size`` (x, y, z) at ``pose``: its top-down hull and height span."""
    hx, hy, hz = (s / 2 for s in size)
    corners = [
        pose.apply((sx * hx, sy * hy, sz * hz))
        for sx in (-1, 1)
        for sy in (-1, 1)
        for sz in (-1, 1)
    ]
    return _hull_shape(model, corners)


def cylinder_shape(model: str, pose: Pose3, radius: float, length: float) -> Shape:
    """A cylinder along its local z: a disc when upright, else the hull of its end rings."""
    zs = [pose.apply((0.0, 0.0, s * length / 2))[2] for s in (-1, 1)]
    if abs(pose.rot[2][2]) > 1 - 1e-9:
        x, y, _ = pose.xyz
        return Disc(model, x, y, radius, min(zs), max(zs))
    ring = [
        pose.apply((radius * math.cos(a), radius * math.sin(a), s * length / 2))
        for a in (i * math.pi / 16 for i in range(32))
        for s in (-1, 1)
    ]
    return _hull_shape(model, ring)


def sphere_shape(model: str, pose: Pose3, radius: float) -> Shape:
    """A sphere: a disc whose cross-section depends on the ray height."""
    x, y, z = pose.xyz
    return Disc(model, x, y, radius, z - radius, z + radius, sphere_z=z)


def _hull_shape(model: str, points: list[tuple[float, float, float]]) -> Polygon:
    return Polygon(
        model,
        convex_hull((p[0], p[1]) for p in points),
        min(p[2] for p in points),
        max(p[2] for p in points),
    )


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
        if model_name in _HARMLESS_INCLUDES:
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


# ---------------------------------------------------------------- ray casting


@dataclass(frozen=True)
class ScanGeometry:
    """The angles of one horizontal scan, in the sensor frame (as the ray sensor's SDF says)."""

    angle_min: float
    angle_max: float
    samples: int
    range_min: float
    range_max: float

    @property
    def increment(self) -> float:
        """Angle between rays; Gazebo spreads ``samples`` rays over [min, max] inclusive."""
        return 0.0 if self.samples <= 1 else (self.angle_max - self.angle_min) / (self.samples - 1)


class RayCaster:
    """Casts horizontal rays against fixed shapes; precomputes what does not change per scan."""

    def __init__(self, shapes: Iterable[Shape]):
        self.shapes = list(shapes)
        self._edges = [s.edges() if isinstance(s, Polygon) else [] for s in self.shapes]
        self._bounds = [s.bound for s in self.shapes]

    def cast(
        self, x: float, y: float, z: float, angle: float, range_min: float, range_max: float
    ) -> float:
        """Distance along one ray from (x, y) at height z to the first surface, inf if none."""
        scan = ScanGeometry(angle, angle, 1, range_min, range_max)
        return self.scan(x, y, z, 0.0, scan)[0]

    def scan(
        self,
        x: float,
        y: float,
        z: float,
        yaw: float,
        geometry: ScanGeometry,
        extra: Sequence[Disc] = (),
        mirrored: bool = False,
    ) -> list[float]:
        """Ranges of every ray of ``geometry`` from a sensor at (x, y, z) heading ``yaw``.

        Rays start at range_min (as Gazebo's do) and report inf when nothing lies within
        range_max. ``extra`` are moving discs (other robots); ``mirrored`` flips the sweep for
        a sensor mounted upside down.
        """
        n = geometry.samples
        sign = -1.0 if mirrored else 1.0
        inc = geometry.increment
        angles = [yaw + sign * (geometry.angle_min + i * inc) for i in range(n)]
        cos_a = [math.cos(a) for a in angles]
        sin_a = [math.sin(a) for a in angles]
        ranges = [math.inf] * n
        rmin, rmax = geometry.range_min, geometry.range_max
        shapes: list[tuple[Shape, list[tuple[Point, Point]], tuple[float, float, float]]] = [
            (s, e, b) for s, e, b in zip(self.shapes, self._edges, self._bounds, strict=True)
        ]
        shapes.extend((d, [], d.bound) for d in extra)
        for shape, edges, (bx, by, br) in shapes:
            if shape.zmin > z or shape.zmax < z:
                continue  # the scan plane passes above or below it
            dist = math.hypot(bx - x, by - y)
            if dist - br > rmax:
                continue
            for i in _window(dist, br, math.atan2(by - y, bx - x), yaw, sign, geometry):
                if edges:
                    t = _hit_polygon(x, y, cos_a[i], sin_a[i], edges, rmin)
                else:
                    assert isinstance(shape, Disc)
                    t = _hit_disc(
                        x, y, cos_a[i], sin_a[i], shape.x, shape.y, shape.radius_at(z), rmin
                    )
                if t < ranges[i]:
                    ranges[i] = t
        return [r if r <= rmax else math.inf for r in ranges]


def _window(
    dist: float, radius: float, bearing: float, yaw: float, sign: float, g: ScanGeometry
) -> Iterable[int]:
    """Indices of the rays that can touch a bounding circle seen at ``bearing``."""
    n = g.samples
    inc = g.increment
    if dist <= radius or n <= 1 or inc == 0:
        return range(n)
    half = math.asin(radius / dist) + 1e-9
    centre = sign * (bearing - yaw) - g.angle_min  # the bearing in scan-angle terms
    step = abs(inc)
    indices: set[int] = set()
    for turn in (-2 * math.pi, 0.0, 2 * math.pi, 4 * math.pi):
        lo_angle, hi_angle = centre + turn - half, centre + turn + half
        if inc < 0:
            lo_angle, hi_angle = -hi_angle, -lo_angle
        lo = max(0, math.ceil(lo_angle / step - 1e-9))
        hi = min(n - 1, math.floor(hi_angle / step + 1e-9))
        if lo <= hi:
            indices.update(range(lo, hi + 1))
    return sorted(indices)


def _hit_disc(
    x: float, y: float, c: float, s: float, cx: float, cy: float, r: float, rmin: float
) -> float:
    if r <= 0:
        return math.inf
    fx, fy = x - cx, y - cy
    b = fx * c + fy * s
    disc = b * b - (fx * fx + fy * fy - r * r)
    if disc < 0:
        return math.inf
    root = math.sqrt(disc)
    near, far = -b - root, -b + root
    if near >= rmin:
        return near
    return far if far >= rmin else math.inf


def _hit_polygon(
    x: float, y: float, c: float, s: float, edges: list[tuple[Point, Point]], rmin: float
) -> float:
    best = math.inf
    for (ax, ay), (bx, by) in edges:
        ex, ey = bx - ax, by - ay
        denom = c * ey - s * ex
        if abs(denom) < 1e-15:
            continue  # parallel to this edge
        wx, wy = ax - x, ay - y
        t = (wx * ey - wy * ex) / denom
        u = (wx * s - wy * c) / denom
        if -1e-12 <= u <= 1 + 1e-12 and rmin <= t < best:
            best = t
    return best


def clearance(
    shapes: Iterable[Shape], x: float, y: float, radius: float, zmin: float, zmax: float
) -> float:
    """How far a robot disc at (x, y) is from touching any shape overlapping [zmin, zmax]."""
    best = math.inf
    for shape in shapes:
        if shape.zmax <= zmin or shape.zmin >= zmax:
            continue
        best = min(best, shape.clearance(x, y) - radius)
    return best


# ---------------------------------------------------------------- noise


@dataclass(frozen=True)
class GaussianNoise:
    """Gazebo's gaussian sensor noise: per-sample N(mean, stddev) plus a bias drawn once."""

    mean: float = 0.0
    stddev: float = 0.0
    bias_mean: float = 0.0
    bias_stddev: float = 0.0

    @property
    def is_zero(self) -> bool:
        """True when applying it changes nothing (saves a random draw per value)."""
        return not (self.mean or self.stddev or self.bias_mean or self.bias_stddev)

    def sampler(self, rng: random.Random) -> NoiseSampler:
        """A noise stream from ``rng``; the bias is drawn now, its sign at random as in Gazebo."""
        bias = 0.0
        if self.bias_mean or self.bias_stddev:
            bias = rng.gauss(self.bias_mean, self.bias_stddev)
            if rng.random() < 0.5:
                bias = -bias
        return NoiseSampler(self, rng, bias)


@dataclass
class NoiseSampler:
    """One sensor axis' noise: deterministic for a given seeded ``rng``."""

    noise: GaussianNoise
    rng: random.Random
    bias: float

    def apply(self, value: float) -> float:
        """``value`` with noise added."""
        if self.noise.is_zero:
            return value
        return value + self.bias + self.rng.gauss(self.noise.mean, self.noise.stddev)


def seeded_rng(seed: int, *names: str) -> random.Random:
    """A random stream per sensor, stable across runs (string seeds hash with SHA-512)."""
    return random.Random(":".join([str(seed), *names]))
