"""ROS 1 differential suite: real-world-style roslaunch files resolved by the real roslaunch
(its Python API under Debian's Python) and by mlaunch's ROS 1 reader, compared field by field:
every node (package, type, name, namespace, args, remaps, env, output, cwd, launch-prefix,
required, respawn, respawn_delay, machine) and every parameter with its value and type.

The same files are also resolved on ROS 2 (the mapping of docs/ros1.md): each node the
mapping does not rewrite gets roslaunch's arguments, launch-prefix, remaps, env, respawn and
required, and as parameters what roslaunch's parameter server holds for it by ROS 1's name
rules (private, relative, searchParam) with the values ROS 2 can hold.

The package trees are in tests/ros1diff (navigation stack, simulator, arm, bridge), plus the
seed's smartcar; each case runs with several argument sets."""

from __future__ import annotations

import itertools
import re
import shlex
import socket
from pathlib import Path
from typing import Any

import pytest
import yaml
from procutil import install_package
from ros1_oracle import typed
from ros1tree import oracle, package_tree, requires_roslaunch

from mlaunch import readers, standins
from mlaunch.resolve.resolver import LabelCounter, ResolveOptions, resolve
from mlaunch.ros import packages
from mlaunch.ros1 import config as ros1_config
from mlaunch.ros1.params import ros2_value
from mlaunch.ros1.server import Server, flat

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


# --- the ROS 2 mapping of the same files ---------------------------------------------------------

# ROS 1 programs the mapping table rewrites (docs/ros1.md, Nodes): their arguments are not
# roslaunch's (robot_state_publisher and joint_state_publisher drop, by ros1.server.DROPPED,
# the parameters ROS 2's do not take).
REWRITTEN = {
    ("rviz", "rviz"),
    ("tf", "static_transform_publisher"),
    ("arbotix_python", "arbotix_driver"),
}
DROPPED = {
    "robot_state_publisher": {"tf_prefix", "use_tf_static"},
    "joint_state_publisher": {"use_gui"},
}
ROS2_PROGRAMS = [
    ("robot_state_publisher", "robot_state_publisher"),
    ("joint_state_publisher", "joint_state_publisher"),
    ("joint_state_publisher_gui", "joint_state_publisher_gui"),
    ("rviz2", "rviz2"),
    ("tf2_ros", "static_transform_publisher"),
    ("gazebo_ros", "spawn_entity.py"),
]


def untyped(found: Any) -> Any:
    kind, value = found
    if kind == "NoneType":
        return None
    if kind == "list":
        return [untyped(v) for v in value]
    if kind == "dict":
        return {k: untyped(v) for k, v in value.items()}
    return value


def oracle_config(expected: dict[str, Any]) -> ros1_config.Config:
    """The oracle's resolution as mlaunch's Config (for the name rules of docs/ros1.md)."""
    config = ros1_config.Config()
    core = ("/rosversion", "/rosdistro")  # roscore.xml's: a ROS 2 run has no ROS 1 core
    config.params = {k: untyped(v) for k, v in expected["params"].items() if k not in core}
    for n in expected["nodes"]:
        config.nodes.append(
            ros1_config.Ros1Node(n["package"], n["type"], n["name"], n["namespace"])
        )
    return config


def programs(root: Path, nodes: list[dict[str, Any]]) -> None:
    """Every node's program in the tree's ament prefix (the plan needs them; none runs)."""
    wanted = {(n["package"], n["type"]) for n in nodes} | set(ROS2_PROGRAMS)
    for package, program in sorted(wanted):
        prefix = root / "ament"
        if not (prefix / "share" / package).exists():
            install_package(prefix, package, {})
        (prefix / "lib" / package).mkdir(parents=True, exist_ok=True)
        path = prefix / "lib" / package / program
        path.write_text("#!/bin/sh\n")
        path.chmod(0o755)


def ros_args(argv: tuple[str, ...]) -> tuple[dict[str, Any], list[tuple[str, str]]]:
    """The parameters (-p rules and params files, as rcl reads them) and remaps of a node."""
    found: dict[str, Any] = {}
    remaps: list[tuple[str, str]] = []
    for flag, value in itertools.pairwise(argv):
        if flag == "-p":
            name, _, text = value.partition(":=")
            found[name] = yaml.safe_load(text)
        elif flag == "--params-file":
            for entry in yaml.safe_load(Path(value).read_text()).values():
                found.update(entry["ros__parameters"])
        elif flag == "-r" and not value.startswith(("__node:=", "__ns:=")):
            src, _, dst = value.partition(":=")
            remaps.append((src, dst))
    return found, remaps


@pytest.mark.parametrize(
    ("case", "launch", "args"),
    [(c, f, a) for c, f, sets in CASES for a in sets],
    ids=lambda v: v if isinstance(v, str) else ",".join(f"{k}={x}" for k, x in v.items()) or "-",
)
def test_ros2_mapping_gives_each_node_what_roslaunch_gives_it(
    tmp_path: Path, case: str, launch: str, args: dict[str, str], monkeypatch: pytest.MonkeyPatch
) -> None:
    root, env = tree(tmp_path, case)
    path = root / launch
    expected = oracle(path, args, env)
    programs(tmp_path, expected["nodes"])
    (tmp_path / "src" / "COLCON_IGNORE").touch()
    for name in ("AMENT_PREFIX_PATH", "ROS_PACKAGE_PATH"):
        monkeypatch.setenv(name, env[name])
    monkeypatch.setattr(standins, "NEEDS", {})
    packages.forget_scans()
    plan = resolve(
        readers.load(str(path)),
        path=str(path),
        arguments=args,
        environ=env,
        options=ResolveOptions(temp_dir=str(tmp_path)),
        labels=LabelCounter(),
    )
    server = Server.of(oracle_config(expected))
    shares = tmp_path / "ament" / "share"
    links = {str(p): str(p.resolve()) for p in shares.iterdir() if p.is_symlink()}

    def real(found: Any) -> Any:
        """$(find) in ROS 2 goes through the ament index: the same folders, by a symlink."""
        if isinstance(found, str):
            for link, target in links.items():
                found = found.replace(link + "/", target + "/")
            return found
        if isinstance(found, (list, tuple)):
            return type(found)(real(v) for v in found)
        if isinstance(found, dict):
            return {k: real(v) for k, v in found.items()}
        return found

    specs = {(s.node.namespace, s.node.name): s for s in plan.processes() if s.node is not None}
    for node in expected["nodes"]:
        if (node["package"], node["type"]) in REWRITTEN:
            continue
        spec = specs[(node["namespace"].rstrip("/") or "/", node["name"])]
        prefix = shlex.split(node["launch_prefix"] or "")
        assert list(spec.argv[: len(prefix)]) == prefix
        own = spec.argv[len(prefix) + 1 : spec.argv.index("--ros-args")]
        assert real(list(own)) == shlex.split(node["args"]), node["name"]
        found, remaps = real(ros_args(spec.argv))
        assert remaps == [tuple(r) for r in node["remaps"]], node["name"]
        for key, value in node["env"]:
            assert spec.env[key] == value
        assert (spec.respawn.mode != "never") == node["respawn"]
        if node["respawn"]:
            assert spec.respawn.delay == node["respawn_delay"]
        assert spec.required == node["required"]
        mine, shared = server.parameters_of(node["name"], node["namespace"], node["package"])
        want = {}
        for name, value in flat({**shared, **mine}).items():
            held, problem = ros2_value(value)
            if problem is None:
                want[name] = held
        missing = {k: v for k, v in want.items() if typed(found.get(k)) != typed(v)}
        extra = {k: v for k, v in found.items() if k not in want}
        assert (missing, extra) == ({}, {}), (node["name"], plan.warnings)
