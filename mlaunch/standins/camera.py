"""The depth camera of a spawned robot: its settings, and depth images ray-cast against the world.

A ``<sensor type="depth">`` (Gazebo classic, with gazebo_ros's camera plugin) or ``depth_camera``
/ ``rgbd_camera`` (gz) is read into ``CameraParams``. ``render_depth`` makes the depth image a
pinhole camera at the sensor's pose would see in the simulator's world: one horizontal ray per
image column against the world's shapes (whose height span decides which rows see them) and the
ground at z = 0, so a flat wall at distance d in front of the camera reads d in every pixel that
sees it. Values follow REP 118: metres as 32FC1 (+inf where nothing is within the far clip), or
millimetres as 16UC1 (0 for no reading). The point cloud is the depth image back-projected in
the optical frame (z forward, x right, y down). Needs numpy (it comes with the ROS wheels).
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from mlaunch.standins.plugins import (
    ModelError,
    expand_topic,
    parse_ros_block,
    plugin_kind,
    read_float,
    read_int,
    read_text,
)
from mlaunch.standins.sensors import Mount
from mlaunch.standins.shapes import Disc, Shape

if TYPE_CHECKING:
    import numpy as np

DEPTH_TYPES = ("depth", "depth_camera", "rgbd_camera", "rgbd")
CLASSIC_CAMERA = ("gazebo_ros_camera", "gazebo_ros_depth_camera")
# Image formats that make the depth image 16-bit millimetres; any other is 32-bit metres.
MILLIMETRE_FORMATS = ("L16", "L_UINT16", "L_INT16")


@dataclass(frozen=True)
class CameraParams:
    """One depth camera: image size and optics, where it sits, and the topics it publishes."""

    name: str
    link: str
    mount: Mount
    update_rate: float
    width: int
    height: int
    hfov: float
    near: float
    far: float
    min_depth: float  # the point cloud keeps depths in [min_depth, max_depth]
    max_depth: float
    encoding: str  # 32FC1 or 16UC1
    frame_id: str
    depth_topic: str
    depth_info_topic: str
    points_topic: str

    @property
    def focal(self) -> float:
        """Focal length in pixels (square pixels), from the horizontal field of view."""
        return self.width / (2.0 * math.tan(self.hfov / 2.0))

    @property
    def centre(self) -> tuple[float, float]:
        """The principal point (cx, cy) gazebo_ros reports: (size + 1) / 2 on both axes."""
        return ((self.width + 1) / 2.0, (self.height + 1) / 2.0)


def parse_depth_camera(
    sensor: ET.Element, link: str, mount: Mount, robot_namespace: str
) -> CameraParams:
    """A depth ``<sensor>`` with its ``<camera>`` block and its gazebo_ros plugin (or gz topic)."""
    name = sensor.get("name", "camera")
    where = f"sensor {name!r} on link {link!r}"
    camera = sensor.find("camera")
    if camera is None:
        raise ModelError(f"{where}: has no <camera> element with the image settings")
    width = read_int(camera, "image/width", 320, where)
    height = read_int(camera, "image/height", 240, where)
    hfov = read_float(camera, "horizontal_fov", 1.047, where)
    near = read_float(camera, "clip/near", 0.1, where)
    far = read_float(camera, "clip/far", 10.0, where)
    if width < 1 or height < 1:
        raise ModelError(f"{where}: image is {width}x{height}; it needs at least one pixel")
    if not 0.0 < hfov < math.pi:
        raise ModelError(f"{where}: <horizontal_fov> is {hfov}; it must be in (0, pi)")
    if not 0.0 <= near < far:
        raise ModelError(f"{where}: clip near {near} / far {far}; need 0 <= near < far")
    fmt = read_text(camera, "image/format", "R_FLOAT32")
    encoding = "16UC1" if fmt.upper() in MILLIMETRE_FORMATS else "32FC1"
    plugin = next(
        (
            p
            for p in sensor.findall("plugin")
            if plugin_kind(p.get("filename", "")) in CLASSIC_CAMERA
        ),
        None,
    )
    if plugin is not None:
        names = parse_ros_block(plugin, robot_namespace)
        prefix = read_text(plugin, "camera_name", name)
        topics = [names.resolve(f"{prefix}/{leaf}") for leaf in _LEAVES]
        frame = read_text(plugin, "frame_name", link)
        min_depth = read_float(plugin, "min_depth", near, where)
        max_depth = read_float(plugin, "max_depth", far, where)
    else:
        base = expand_topic(read_text(sensor, "topic", name), robot_namespace or "/", name)
        topics = [base, f"{base}/camera_info", f"{base}/points"]
        frame = read_text(sensor, "gz_frame_id", read_text(sensor, "frame_id", link))
        min_depth, max_depth = near, far
    return CameraParams(
        name=name,
        link=link,
        mount=mount,
        update_rate=read_float(sensor, "update_rate", 0.0, where),
        width=width,
        height=height,
        hfov=hfov,
        near=near,
        far=far,
        min_depth=min_depth,
        max_depth=max_depth,
        encoding=encoding,
        frame_id=frame,
        depth_topic=topics[0],
        depth_info_topic=topics[1],
        points_topic=topics[2],
    )


# gazebo_ros_camera's topics under <camera_name>/ for a depth sensor.
_LEAVES = ("depth/image_raw", "depth/camera_info", "points")


class DepthRenderer:
    """Depth images of one camera; what does not change between frames is computed once."""

    def __init__(self, params: CameraParams, shapes: Sequence[Shape]) -> None:
        import numpy as np

        self.params = params
        self.shapes = list(shapes)
        f = params.focal
        cx, cy = params.centre
        # Rays through pixel centres as the published camera info describes them (column u at
        # (u - cx) / f), so depth_image_proc and the point cloud agree with the image.
        self.a = (np.arange(params.width, dtype=np.float64) - cx) / f  # right of the axis
        self.b = (np.arange(params.height, dtype=np.float64) - cy) / f  # below the axis
        # Forward (optical z) distance per unit of horizontal distance along each column's ray.
        self.forward = 1.0 / np.sqrt(1.0 + self.a * self.a)
        self.arctan_a = np.arctan(self.a)
        self.b_column = self.b[:, None]
        self.a32 = self.a.astype(np.float32)[None, :]
        self.b32 = self.b.astype(np.float32)[:, None]
        self._ground_cache: dict[float, Any] = {}

    def render(self, x: float, y: float, z: float, yaw: float, extra: Sequence[Disc] = ()) -> Any:
        """The depth (metres along the optical axis, float32) per pixel of a camera at a pose.

        Per shape the work is one horizontal hit per column, then a masked copy of that
        column's depth into the rows whose line of sight meets the shape within its height
        span; nothing else is recomputed per frame.
        """
        import numpy as np

        p = self.params
        depth = self._ground(z).copy()
        # Each column's horizontal ray: straight ahead is yaw, image right is clockwise.
        angles = yaw - self.arctan_a
        dx, dy = np.cos(angles), np.sin(angles)
        reach = p.far / float(self.forward.min())
        for shape in [*self.shapes, *extra]:
            bx, by, br = shape.bound
            if math.hypot(bx - x, by - y) - br > reach:
                continue
            ahead = _hits(shape, x, y, dx, dy, z) * self.forward  # optical depth per column
            columns = np.nonzero(ahead <= p.far)[0]
            if columns.size == 0:
                continue
            c0, c1 = int(columns[0]), int(columns[-1]) + 1
            near = ahead[c0:c1]
            # Row v sees the hit at height z - b[v] * depth: inside [zmin, zmax] or not.
            with np.errstate(divide="ignore", invalid="ignore"):
                lo, hi = (z - shape.zmax) / near, (z - shape.zmin) / near
            seen = (self.b_column >= lo) & (self.b_column <= hi)
            window = depth[:, c0:c1]
            value = np.where(near < p.near, -np.inf, near).astype(np.float32)
            np.copyto(window, np.broadcast_to(value, window.shape), where=seen & (value < window))
        return depth

    def _ground(self, z: float) -> Any:
        """What the camera sees with nothing in the way: the ground, for rows that look down."""
        import numpy as np

        cached = self._ground_cache.get(z)
        if cached is None:
            p = self.params
            rows = np.full(p.height, np.inf)
            down = self.b > 1e-12
            rows[down] = z / self.b[down]
            rows[rows > p.far] = np.inf
            rows[rows < p.near] = -np.inf
            cached = np.ascontiguousarray(
                np.broadcast_to(rows.astype(np.float32)[:, None], (p.height, p.width))
            )
            self._ground_cache = {z: cached}  # one camera height per robot: keep the last
        return cached

    def image_bytes(self, depth: np.ndarray) -> bytes:
        """The depth image's data in the camera's encoding (little-endian)."""
        import numpy as np

        if self.params.encoding == "16UC1":
            mm = np.where(np.isfinite(depth), np.round(depth * 1000.0), 0.0)
            return np.clip(mm, 0, 65535).astype("<u2").tobytes()
        return depth.astype("<f4", copy=False).tobytes()

    def cloud_bytes(self, depth: np.ndarray) -> bytes:
        """x, y, z float32 per pixel in the optical frame; NaN outside [min_depth, max_depth]."""
        import numpy as np

        p = self.params
        valid = (depth >= p.min_depth) & (depth <= p.max_depth)  # false for inf and -inf
        d = np.where(valid, depth, np.float32(np.nan))
        points = np.empty((p.height, p.width, 3), dtype="<f4")
        np.multiply(self.a32, d, out=points[..., 0])
        np.multiply(self.b32, d, out=points[..., 1])
        points[..., 2] = d
        return points.tobytes()


def _hits(shape: Shape, x: float, y: float, dx: Any, dy: Any, z: float) -> Any:
    """Horizontal distance along each ray (dx, dy) from (x, y) to the shape, inf where none."""
    import numpy as np

    if isinstance(shape, Disc):
        # A sphere's cross-section at the camera's height stands for its whole height span.
        r = shape.radius_at(z) or shape.radius
        fx, fy = x - shape.x, y - shape.y
        b = fx * dx + fy * dy
        disc = b * b - (fx * fx + fy * fy - r * r)
        root = np.sqrt(np.maximum(disc, 0.0))
        near, far = -b - root, -b + root
        t = np.where(near >= 0, near, np.where(far >= 0, 0.0, np.inf))  # inside: touching
        return np.where(disc >= 0, t, np.inf)
    best = np.full(dx.shape, np.inf)
    for (ax, ay), (bx, by) in shape.edges():
        ex, ey = bx - ax, by - ay
        denom = dx * ey - dy * ex
        with np.errstate(divide="ignore", invalid="ignore"):
            t = ((ax - x) * ey - (ay - y) * ex) / denom
            u = ((ax - x) * dy - (ay - y) * dx) / denom
        hit = (np.abs(denom) > 1e-15) & (u >= -1e-12) & (u <= 1 + 1e-12) & (t >= 0)
        best = np.where(hit & (t < best), t, best)
    return best


def camera_info(params: CameraParams, msg: Any) -> Any:
    """Fill a sensor_msgs/CameraInfo with the pinhole model gazebo_ros reports (no distortion)."""
    f = params.focal
    cx, cy = params.centre
    msg.header.frame_id = params.frame_id
    msg.width, msg.height = params.width, params.height
    msg.distortion_model = "plumb_bob"
    msg.d = [0.0] * 5
    msg.k = [f, 0.0, cx, 0.0, f, cy, 0.0, 0.0, 1.0]
    msg.r = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
    msg.p = [f, 0.0, cx, 0.0, 0.0, f, cy, 0.0, 0.0, 0.0, 1.0, 0.0]
    return msg
