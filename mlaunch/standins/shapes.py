"""What the simulator sees of a world and a robot: 3D poses, and shapes seen from above.

Every collision shape becomes a top-down disc (upright cylinders, spheres) or convex polygon
(boxes, lying cylinders) with its height span. Pure Python.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

Point = tuple[float, float]
Rotation = tuple[tuple[float, float, float], ...]  # 3x3, row-major


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
