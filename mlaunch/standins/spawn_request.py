"""Spawn requests the simulator stand-in takes on /mlaunch_sim/spawn: parsed and checked.

The spawner stand-in sends one JSON object per model (see sim.py for the protocol); a request
that is not usable is a ValueError whose message the simulator sends back. Pure Python.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from dataclasses import dataclass


@dataclass
class SpawnRequest:
    """A validated ``/mlaunch_sim/spawn`` message."""

    name: str
    urdf: str
    pose: tuple[float, float, float, float, float, float]
    id: str | None = None
    robot_namespace: str = ""
    allow_renaming: bool = False


def parse_spawn_request(text: str) -> SpawnRequest:
    """Decode and check a spawn request; ValueError says what is wrong."""
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise ValueError(f"spawn request is not JSON: {exc}") from None
    if not isinstance(data, dict):
        raise ValueError(f"spawn request must be a JSON object, got {type(data).__name__}")
    name = data.get("name")
    if not isinstance(name, str) or not name:
        raise ValueError(f"spawn request 'name' must be a non-empty string, got {name!r}")
    urdf = data.get("urdf")
    if not isinstance(urdf, str):
        raise ValueError(f"spawn request 'urdf' must be the URDF text, got {type(urdf).__name__}")
    pose = []
    for key in ("x", "y", "z", "roll", "pitch", "yaw"):
        value = data.get(key, 0.0)
        if (
            isinstance(value, bool)
            or not isinstance(value, int | float)
            or not math.isfinite(value)
        ):
            raise ValueError(f"spawn request {key!r} must be a finite number, got {value!r}")
        pose.append(float(value))
    request_id = data.get("id")
    namespace = data.get("robot_namespace") or ""
    if not isinstance(namespace, str):
        raise ValueError(f"spawn request 'robot_namespace' must be a string, got {namespace!r}")
    x, y, z, roll, pitch, yaw = pose
    return SpawnRequest(
        name=name,
        urdf=urdf,
        pose=(x, y, z, roll, pitch, yaw),
        id=None if request_id is None else str(request_id),
        robot_namespace=namespace,
        allow_renaming=bool(data.get("allow_renaming", False)),
    )


def free_name(name: str, taken: Mapping[str, object]) -> str:
    """``name`` or, when taken, ``name_1``, ``name_2``... (gz create -allow_renaming)."""
    if name not in taken:
        return name
    n = 1
    while f"{name}_{n}" in taken:
        n += 1
    return f"{name}_{n}"
