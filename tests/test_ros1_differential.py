"""ROS 1 differential suite: real-world-style roslaunch files resolved by the real roslaunch
(its Python API under Debian's Python) and by mlaunch's ROS 1 reader, compared field by field:
every node (package, type, name, namespace, args, remaps, env, output, cwd, launch-prefix,
required, respawn, respawn_delay, machine) and every parameter with its value and type.

The package trees are in tests/ros1diff (navigation stack, simulator, arm, bridge), plus the
seed's smartcar; each case runs with several argument sets."""

from __future__ import annotations

import re
import socket
from pathlib import Path
from typing import Any

import pytest
from ros1tree import oracle, package_tree, requires_roslaunch

from mlaunch.ros1 import config as ros1_config

REPO = Path(__file__).resolve().parent.parent
SMARTCAR = "smartcar_display.launch"

pytestmark = requires_roslaunch

# (case folder, launch file in it, argument sets)
CASES: list[tuple[str, str, list[dict[str, str]]]] = [
    (
        "nav",
        "nav_bringup/launch/navigation.launch",
        [{}, {"model": "waffle", "move_forward_only": "true", "open_rviz": "false"}],
    ),
    (
        "sim",
        "rrbot_gazebo/launch/rrbot_world.launch",
        [{}, {"paused": "true", "gui": "false", "debug": "true", "use_sim_time": "False"}],
    ),
    (
        "arm",
        "panda_moveit_config/launch/demo.launch",
        [{}, {"use_gui": "true", "debug": "true", "pipeline": "chomp", "use_rviz": "false"}],
    ),
    ("bridge", "ros1_bridge/launch/bridges.launch", [{}, {"queue": "1", "web": "false"}]),
    ("bridge", "rosbridge_server/launch/rosbridge_websocket.launch", [{"ssl": "true"}]),
    ("smartcar", SMARTCAR, [{}, {"gui": "true"}]),
]


def typed(value: Any) -> Any:
    """A value with its type, as tests/ros1_oracle.py writes roslaunch's."""
    if isinstance(value, bool):
        return ["bool", value]
    if isinstance(value, int):
        return ["int", value]
    if isinstance(value, float):
        return ["double", value]
    if isinstance(value, str):
        return ["str", value]
    if isinstance(value, list):
        return ["list", [typed(v) for v in value]]
    if isinstance(value, dict):
        return ["dict", {k: typed(v) for k, v in value.items()}]
    return [type(value).__name__, str(value)]


def mlaunch_view(config: ros1_config.Config) -> dict[str, Any]:
    nodes = [
        {
            "package": n.package,
            "type": n.type,
            "name": n.name,
            "namespace": n.namespace,
            "args": n.args,
            "remaps": [list(r) for r in n.remaps],
            "env": [list(e) for e in n.env],
            "output": n.output,
            "cwd": n.cwd,
            "launch_prefix": n.launch_prefix,
            "required": n.required,
            "respawn": n.respawn,
            "respawn_delay": n.respawn_delay,
            "machine": n.machine,
        }
        for n in config.nodes
    ]
    params = {k: typed(v) for k, v in config.params.items()}
    core = [n.full_name for n in config.core_nodes]
    return {"nodes": nodes, "params": params, "clear_params": config.clear_params, "core": core}


_ANON = re.compile(r"_" + re.escape(re.sub(r"[.\-:]", "_", socket.gethostname())) + r"_\d+_\d+")


def anonymous(found: Any) -> Any:
    """$(anon) names differ from run to run: their unique part is cut."""
    if isinstance(found, str):
        return _ANON.sub("_ANON", found)
    if isinstance(found, list):
        return [anonymous(v) for v in found]
    if isinstance(found, dict):
        return {anonymous(k): anonymous(v) for k, v in found.items()}
    return found


def tree(tmp_path: Path, case: str) -> tuple[Path, dict[str, str]]:
    if case == "smartcar":  # the seed's file and this repository's package
        seed = (REPO / "robots" / "smartcar_description", REPO / "launches" / SMARTCAR)
        return tmp_path / "src", package_tree(tmp_path, extra=seed)
    return tmp_path / "src" / case, package_tree(tmp_path, case)


@pytest.mark.parametrize(
    ("case", "launch", "args"),
    [(c, f, a) for c, f, sets in CASES for a in sets],
    ids=lambda v: v if isinstance(v, str) else ",".join(f"{k}={x}" for k, x in v.items()) or "-",
)
def test_mlaunch_resolves_as_roslaunch(
    tmp_path: Path, case: str, launch: str, args: dict[str, str]
) -> None:
    root, env = tree(tmp_path, case)
    path = root / launch
    expected = anonymous(oracle(path, args, env))
    found = anonymous(mlaunch_view(ros1_config.load(str(path), args, environ=env, core=True)))
    assert found["params"].keys() == expected["params"].keys()
    for key, value in expected["params"].items():
        assert found["params"][key] == value, key
    assert len(found["nodes"]) == len(expected["nodes"])
    for mine, theirs in zip(found["nodes"], expected["nodes"], strict=True):
        assert mine == theirs
    assert found["clear_params"] == expected["clear_params"]
    assert found["core"] == expected["core"]
