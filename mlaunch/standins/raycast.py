"""Horizontal ray casting against shapes seen from above, and Gazebo's sensor noise.

The lidar, the depth camera and collision checks all ask here: where does a ray from a point at
some height first meet a shape, how far is a disc from touching one. Pure Python.
"""

from __future__ import annotations

import math
import random
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

from mlaunch.standins.shapes import Disc, Point, Polygon, Shape

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
