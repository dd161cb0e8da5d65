"""The simulator's world on ROS, for the viewer: what it publishes and how the viewer reads it.

The simulator stand-in publishes the static shapes it ray-casts and collides with on
``/mlaunch_sim/world`` (reliable + transient_local, depth 1, std_msgs/String of JSON), again
whenever a robot is spawned, so that the viewer stand-in draws the walls under the robot and
its scan. Gazebo has no such topic; this is the stand-ins' own protocol, like the spawn topics.

The document::

    {"name": "jt_world", "frame": "world",
     "shapes": [{"model": "wall_east", "type": "polygon", "points": [[x, y], ...],
                 "zmin": 0.0, "zmax": 0.5},
                {"model": "pillar", "type": "circle", "x": 1.0, "y": 2.0, "r": 0.1,
                 "zmin": 0.0, "zmax": 1.0}],
     "origins": {"odom": [x, y, yaw]}}

``origins`` says where each odometry frame of a spawned robot starts in the world: at the
origin for world (ground truth) odometry, at the spawn pose for encoder odometry. Pure Python.
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterable
from typing import TYPE_CHECKING, Any

from mlaunch.standins.shapes import Disc, Shape
from mlaunch.standins.viewer_tf import compose, invert

if TYPE_CHECKING:
    from mlaunch.standins.simulation import SimRobot
    from mlaunch.standins.world import World

WORLD_TOPIC = "/mlaunch_sim/world"
WORLD_FRAME = "world"
DIGITS = 5  # 10 micrometres: finer than anything drawn, and a compact document

Pose2D = tuple[float, float, float]


def shape_json(shape: Shape) -> dict[str, Any]:
    """One shape of the world, seen from above, as the document holds it."""
    span = {"zmin": round(shape.zmin, DIGITS), "zmax": round(shape.zmax, DIGITS)}
    if isinstance(shape, Disc):
        x, y, r = (round(v, DIGITS) for v in (shape.x, shape.y, shape.radius))
        return {"model": shape.model, "type": "circle", "x": x, "y": y, "r": r, **span}
    points = [[round(x, DIGITS), round(y, DIGITS)] for x, y in shape.points]
    return {"model": shape.model, "type": "polygon", "points": points, **span}


def world_message(world: World, robots: Iterable[SimRobot], run: str = "") -> str:
    """The JSON text the simulator publishes for its world and its robots' odometry frames;
    ``run`` names this start of the simulator (the viewer sees a restart when it changes)."""
    return json.dumps(
        {
            "name": world.name,
            "run": run,
            "frame": WORLD_FRAME,
            "shapes": [shape_json(s) for s in world.shapes],
            # Not rounded: a yaw off by 1e-5 would move a wall 10 m away by 0.1 mm.
            "origins": {frame: list(pose) for frame, pose in odometry_origins(robots).items()},
        },
        separators=(",", ":"),
    )


def odometry_origins(robots: Iterable[SimRobot]) -> dict[str, Pose2D]:
    """Where each robot's odometry frame starts in the world: encoder odometry (source 0) at
    the spawn pose, world odometry (Gazebo's ground truth) at the world's origin."""
    origins: dict[str, Pose2D] = {}
    for robot in robots:
        drive = robot.spec.drive
        if drive is None or not (drive.publish_odom or drive.publish_odom_tf):
            continue
        start = robot.spawn if drive.odometry_source == 0 else None
        pose = (start.x, start.y, start.yaw) if start is not None else (0.0, 0.0, 0.0)
        origins.setdefault(drive.odometry_frame, pose)
    return origins


class WorldPicture:
    """The last world the simulator published, as the viewer keeps it (not thread-safe:
    ViewerState's lock guards it)."""

    def __init__(self) -> None:
        self.name = ""
        self.shapes: list[dict[str, Any]] = []
        self.origins: dict[str, Pose2D] = {}
        self.error: str | None = None
        self.seen = False
        self.run = ""  # the simulator start that published it

    def set(self, text: str) -> bool:
        """Take a published document; a malformed one keeps the last good world and says why.

        True when it comes from a new start of the simulator (the one before was restarted)."""
        try:
            data = json.loads(text)
            shapes = [_checked(s) for s in data["shapes"]]
            origins = {str(k): _pose(v) for k, v in data.get("origins", {}).items()}
            name, run = str(data.get("name", "")), str(data.get("run", ""))
        except (ValueError, TypeError, KeyError, AttributeError) as exc:
            self.error = f"world from {WORLD_TOPIC} not understood: {type(exc).__name__}: {exc}"
            return False
        restarted = self.seen and run != self.run
        self.name, self.shapes, self.origins, self.error = name, shapes, origins, None
        self.seen, self.run = True, run
        return restarted

    def in_frame(self, frame: str) -> dict[str, Any] | None:
        """The world's shapes in ``frame`` (an odometry frame the simulator named, else the
        world's own: Gazebo's world odometry starts at the world's origin)."""
        if not self.seen:
            return None
        origin = self.origins.get(frame) or self.origins.get(frame.lstrip("/"))
        to_frame = invert(origin) if origin else (0.0, 0.0, 0.0)
        return {
            "name": self.name,
            "frame": frame,
            "shapes": [_moved_shape(to_frame, s) for s in self.shapes],
        }


def _checked(shape: Any) -> dict[str, Any]:
    """A shape of the document, with numbers where numbers belong (else TypeError/KeyError)."""
    kind = shape["type"]
    out: dict[str, Any] = {"model": str(shape.get("model", "")), "type": kind}
    out["zmin"], out["zmax"] = float(shape["zmin"]), float(shape["zmax"])
    if kind == "circle":
        out["x"], out["y"], out["r"] = (float(shape[k]) for k in ("x", "y", "r"))
    elif kind == "polygon":
        out["points"] = [(float(x), float(y)) for x, y in shape["points"]]
    else:
        raise ValueError(f"shape type {kind!r} (expected circle or polygon)")
    return out


def _pose(value: Any) -> Pose2D:
    x, y, yaw = (float(v) for v in value)
    if not all(math.isfinite(v) for v in (x, y, yaw)):
        raise ValueError(f"origin {value!r} is not finite")
    return (x, y, yaw)


def _moved_shape(transform: Pose2D, shape: dict[str, Any]) -> dict[str, Any]:
    def moved(x: float, y: float) -> list[float]:
        mx, my, _ = compose(transform, (x, y, 0.0))
        return [round(mx, DIGITS), round(my, DIGITS)]

    out = dict(shape)
    if shape["type"] == "circle":
        out["x"], out["y"] = moved(shape["x"], shape["y"])
    else:
        out["points"] = [moved(x, y) for x, y in shape["points"]]
    return out
