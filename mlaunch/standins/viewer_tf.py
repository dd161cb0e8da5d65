"""What the viewer stand-in adds to odometry: the TF tree seen from above, and the depth image.

``PlanarTf`` keeps the latest transform of every frame from /tf and /tf_static, projected on
the ground plane (x, y, yaw), and answers where one frame is in another, as a tf2 buffer would
at the latest time. ``DepthPicture`` turns a depth image (32FC1 metres or 16UC1 millimetres) into
a small grey PNG for the page: near is bright, far is dark, no reading is black. Pure Python
apart from numpy, which comes with the ROS wheels.
"""

from __future__ import annotations

import math
import struct
import zlib
from typing import Any

Pose2D = tuple[float, float, float]  # x, y, yaw

PICTURE_WIDTH = 160  # the page shows the depth image this wide, whatever the camera's size


def compose(a: Pose2D, b: Pose2D) -> Pose2D:
    """Pose b (given in a's frame) in a's parent frame."""
    c, s = math.cos(a[2]), math.sin(a[2])
    return (a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], a[2] + b[2])


def invert(a: Pose2D) -> Pose2D:
    """The parent frame's pose in a's frame."""
    c, s = math.cos(a[2]), math.sin(a[2])
    return (-(c * a[0] + s * a[1]), s * a[0] - c * a[1], -a[2])


class PlanarTf:
    """The latest transform per child frame, from /tf and /tf_static, seen from above."""

    def __init__(self) -> None:
        self.parent: dict[str, tuple[str, Pose2D]] = {}

    def set(self, parent: str, child: str, pose: Pose2D) -> None:
        self.parent[child.lstrip("/")] = (parent.lstrip("/"), pose)

    def _chain(self, frame: str) -> list[tuple[str, Pose2D]]:
        """(frame, pose of frame in the root) from ``frame`` up to its root, frame first."""
        chain: list[tuple[str, Pose2D]] = []
        seen = set()
        while frame in self.parent and frame not in seen:
            seen.add(frame)
            parent, pose = self.parent[frame]
            chain.append((frame, pose))
            frame = parent
        chain.append((frame, (0.0, 0.0, 0.0)))
        return chain

    def lookup(self, target: str, source: str) -> Pose2D | None:
        """The pose of frame ``source`` in frame ``target``, or None when they are not connected."""
        target, source = target.lstrip("/"), source.lstrip("/")
        up_source, up_target = self._chain(source), self._chain(target)
        if up_source[-1][0] != up_target[-1][0]:
            return None
        return compose(invert(_to_root(up_target)), _to_root(up_source))

    def frames(self) -> list[str]:
        return sorted({*self.parent, *(p for p, _ in self.parent.values())})


def _to_root(chain: list[tuple[str, Pose2D]]) -> Pose2D:
    pose: Pose2D = (0.0, 0.0, 0.0)
    for _, step in reversed(chain[:-1]):
        pose = compose(pose, step)
    return pose


def yaw_of(qx: float, qy: float, qz: float, qw: float) -> float:
    """Heading of a quaternion (rotation about z), as rviz draws it top-down."""
    return math.atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz))


def planar(translation: Any, rotation: Any) -> Pose2D:
    """A geometry_msgs Transform's translation and rotation, seen from above."""
    q = rotation
    return (translation.x, translation.y, yaw_of(q.x, q.y, q.z, q.w))


class DepthPicture:
    """The latest depth image, kept small as 8-bit grey, and its PNG made on request."""

    def __init__(self) -> None:
        self.grey: Any = None
        self.seq = 0
        self.size = (0, 0)
        self.encoding = ""
        self._png: bytes | None = None

    def set(self, width: int, height: int, encoding: str, data: Any, far: float) -> None:
        """Take a sensor_msgs/Image's fields; other encodings than 32FC1/16UC1 are ignored."""
        import numpy as np

        kinds = {"32FC1": ("<f4", 1.0), "16UC1": ("<u2", 0.001)}
        if encoding not in kinds or width * height == 0:
            return
        dtype, scale = kinds[encoding]
        depth = np.frombuffer(bytes(data), dtype=dtype, count=width * height).reshape(height, width)
        step = max(1, math.ceil(width / PICTURE_WIDTH))
        metres = depth[::step, ::step].astype(np.float32) * scale
        valid = np.isfinite(metres) & (metres > 0)
        reach = far if far > 0 else float(metres[valid].max()) if valid.any() else 1.0
        shade = np.where(valid, 255.0 * (1.0 - np.clip(metres / reach, 0.0, 1.0)), 0.0)
        self.grey = np.ascontiguousarray(shade.astype(np.uint8))
        self.size, self.encoding = (width, height), encoding
        self.seq += 1
        self._png = None

    def png(self) -> bytes | None:
        """The picture as a PNG (8-bit greyscale), or None before the first image."""
        if self.grey is None:
            return None
        if self._png is None:
            self._png = grey_png(self.grey)
        return self._png


def grey_png(grey: Any) -> bytes:
    """An 8-bit greyscale PNG of a 2D uint8 array (no filter, zlib level 6)."""
    height, width = grey.shape
    rows = b"".join(b"\x00" + grey[row].tobytes() for row in range(height))

    def chunk(kind: bytes, body: bytes) -> bytes:
        return (
            struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))
        )

    header = struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)
    return (
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", header)
        + chunk(b"IDAT", zlib.compress(rows, 6))
        + chunk(b"IEND", b"")
    )
