"""``--print --format json``: the values are right. A node's parameters (files and their
contents, typed), environment changes, origins, respawn and the stop ladder; the argv the spawned
process gets; deferred parts as written; machines, launch prefixes, handlers and events; values
JSON cannot spell.
"""

from __future__ import annotations

import json
import signal
from pathlib import Path

from plan_doc import (
    LAUNCHES,
    PREFIX,
    absolute_origin,
    dump_package,
    env,
    plan_of,
    processes,
    validate,
)
from procutil import Running, mlaunch, wait_until

__all__ = ["env"]  # the fixture, imported for pytest


def _origin_line(path: Path, marker: str) -> int:
    """The line of the ``Node(`` call whose arguments contain ``marker``."""
    lines = path.read_text().splitlines()
    at = next(i for i, line in enumerate(lines) if marker in line)
    return next(i for i in range(at, -1, -1) if "Node(" in lines[i]) + 1


def test_node_values(env: dict[str, str]) -> None:
    path = LAUNCHES / "examples" / "talker_listener.launch.py"
    document = plan_of(str(path), "rate:=7.5", env=env)
    validate(document)
    talker = processes(document)["talker-1"]
    assert talker["origin"] == {
        "file": "launches/examples/talker_listener.launch.py",
        "line": _origin_line(path, 'executable="talker"'),
    }
    assert talker["node"] == {
        "name": "talker",
        "namespace": "/robot1",
        "full_name": "/robot1/talker",
        "package": "mlaunch_demo",
        "executable": "talker",
        "lifecycle": False,
        "autostart": False,
    }
    assert talker["env"]["set"]["TALKER_MODE"] == "demo"
    assert talker["env"]["unset"] == []
    assert talker["respawn"]["mode"] == "always" and talker["respawn"]["delay"] == 2.0
    assert talker["respawn"]["max_retries"] is None
    assert talker["output"] == "screen"
    assert talker["remaps"] == [
        {"from": "/rosout_agg", "to": "rosout_all"},
        {"from": "chatter", "to": "chat"},
    ]
    rule, *files = talker["parameters"]
    assert rule == {"kind": "value", "name": "use_sim_time", "value": False, "type": "bool"}
    assert [f["path"] for f in files] == [f"<run-temp>/{i}" for i in range(1, 5)]
    assert all(f["temporary"] and f["error"] is None for f in files)
    given = [(p["node"], p["name"], p["value"], p["type"]) for f in files for p in f["parameters"]]
    assert given == [
        ("/robot1/talker", "rate", 7.5, "double"),
        ("/robot1/talker", "greeting", "hello", "string"),
        ("/robot1/talker", "qos.depth", 10, "integer"),
        ("/robot1/talker", "qos.reliable", True, "bool"),
        ("/robot1/talker", "frames", ["base", "odom", "map"], "string[]"),
    ]
    # The file as written: launch_ros flattens nested maps to dotted names.
    assert files[2]["contents"] == {
        "/robot1/talker": {"ros__parameters": {"qos.depth": 10, "qos.reliable": True}}
    }
    # A params file of the package: its own path and its parsed contents.
    listener = processes(document)["listener-2"]
    (shipped,) = [p for p in listener["parameters"] if p["kind"] == "file"]
    assert not shipped["temporary"]
    assert shipped["path"] == str(PREFIX / "share/mlaunch_demo/config/listener.yaml")
    config = PREFIX / "share/mlaunch_demo/config/listener.yaml"
    import yaml

    assert shipped["contents"] == yaml.safe_load(config.read_text())
    monitor = processes(document)["monitor-3"]
    assert monitor["stop"] == {
        "sigterm_timeout": 1.0,
        "sigkill_timeout": 1.0,
        "ladder": [
            {"signal": "SIGINT", "after": 0.0},
            {"signal": "SIGTERM", "after": 1.0},
            {"signal": "SIGKILL", "after": 2.0},
        ],
    }
    args = {a["name"]: a for a in document["arguments"]}
    assert args["rate"]["value"] == "7.5" and args["rate"]["given"]
    assert args["rate"]["default"] == "5.0"
    assert args["use_sim"]["choices"] == ["true", "false"] and not args["use_sim"]["given"]


LAUNCH = """
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, SetEnvironmentVariable, UnsetEnvironmentVariable
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

def generate_launch_description():
    return LaunchDescription([
        DeclareLaunchArgument('mode', default_value='fast'),
        UnsetEnvironmentVariable('GONE'),
        Node(package='demo', executable='dump', name='dumper', namespace='ns',
             parameters=[{'speed': 2.5, 'tags': ['a', 'b']}, {'inner': {'depth': 3}}],
             remappings=[('in', 'out')], arguments=['--flag', 'x y'],
             additional_env={'DUMP_MODE': LaunchConfiguration('mode')},
             output='screen', respawn=True, respawn_max_retries=2),
    ])
"""


def test_argv_and_params_are_what_gets_spawned(tmp_path: Path, env: dict[str, str]) -> None:
    prefix = dump_package(tmp_path)
    env = {**env, "AMENT_PREFIX_PATH": str(prefix), "GONE": "here"}
    launch = tmp_path / "dump.launch.py"
    launch.write_text(LAUNCH)
    document = plan_of(str(launch), "mode:=slow", env=env)
    validate(document)
    (process,) = processes(document).values()
    # Only what differs from mlaunch's own environment (PYTHONUNBUFFERED may be inherited).
    assert process["env"]["set"]["DUMP_MODE"] == "slow"
    assert process["env"]["set"]["RCUTILS_LOGGING_BUFFERED_STREAM"] == "1"
    assert "HOME" not in process["env"]["set"]
    assert process["env"]["unset"] == ["GONE"]
    assert process["respawn"]["max_retries"] == 2
    assert absolute_origin(process["origin"]) == {
        "file": str(launch),
        "line": LAUNCH.splitlines().index(
            next(line for line in LAUNCH.splitlines() if "Node(" in line)
        )
        + 1,
    }
    run = Running(mlaunch(str(launch), "mode:=slow"), env=env, cwd=str(tmp_path))
    dumped = prefix / "lib/demo/argv.json"
    try:
        assert wait_until(dumped.exists, timeout=20), run.text
    finally:
        run.signal(signal.SIGINT)
        run.finish()
    seen = json.loads(dumped.read_text())
    assert seen["env"] == {"DUMP_MODE": "slow", "GONE": None}
    # The spawned argv, with the run's params files named as the plan names them.
    temp: dict[str, str] = {}
    for item in seen["argv"]:
        if "/launch_params_" in item:
            temp[item] = f"<run-temp>/{len(temp) + 1}"
    assert [temp.get(a, a) for a in seen["argv"]] == process["argv"]
    import yaml

    files = [p for p in process["parameters"] if p["kind"] == "file"]
    assert [yaml.safe_load(text) for text in seen["files"]] == [f["contents"] for f in files]
    assert files[1]["parameters"] == [
        {"node": "/ns/dumper", "name": "inner.depth", "value": 3, "type": "integer"}
    ]
    assert process["remaps"] == [{"from": "in", "to": "out"}]


DEFERRED = """
from launch import LaunchDescription
from launch.actions import ExecuteProcess, LogInfo, RegisterEventHandler, TimerAction, Shutdown
from launch.event_handlers import OnProcessExit
from launch_ros.actions import LifecycleNode
from launch_ros.event_handlers import OnStateTransition
from mlaunch.launch_ros.lifecycle_sequence import LifecycleSequence
from mlaunch.commands.smoke import Expect

def generate_launch_description():
    first = ExecuteProcess(cmd=['true'], name='first', on_exit=[LogInfo(msg='bye')])
    managed = LifecycleNode(package='demo', executable='dump', name='managed', namespace='',
                            autostart=True)
    return LaunchDescription([
        first,
        RegisterEventHandler(OnProcessExit(target_action=first,
                                           on_exit=[ExecuteProcess(cmd=['echo', 'after'])])),
        TimerAction(period=2.5, actions=[LogInfo(msg='late'), Shutdown(reason='done')]),
        managed,
        LifecycleSequence(nodes=['managed'], timeout=4),
        RegisterEventHandler(OnStateTransition(target_lifecycle_node=managed, goal_state='active',
                                               entities=[LogInfo(msg='up')])),
        Expect(topic='/scan', rate=5.0, within=9),
        LogInfo(msg='now'),
    ])
"""


def test_deferred_parts_are_shown_as_written(tmp_path: Path, env: dict[str, str]) -> None:
    prefix = dump_package(tmp_path)
    env = {**env, "AMENT_PREFIX_PATH": str(prefix)}
    launch = tmp_path / "deferred.launch.py"
    launch.write_text(DEFERRED)
    document = plan_of(str(launch), env=env)
    validate(document)
    kinds = [s["kind"] for s in document["steps"]]
    assert kinds == [
        "process",
        "handler",
        "timer",
        "process",
        "lifecycle_sequence",
        "handler",
        "expectation",
        "log",
    ]
    first, handler, timer, managed, sequence, transition, expect, log = document["steps"]
    assert first["required"] is False
    assert [a["action"] for a in first["on_exit"]["actions"]] == ["LogInfo"]
    assert handler["event"] == "process_exit" and handler["start"] == "deferred"
    assert handler["target"].startswith("ExecuteProcess(") and not handler["any_process"]
    (after,) = handler["actions"]
    assert after["action"] == "ExecuteProcess" and "after" in after["summary"]
    assert timer["period"] == 2.5
    assert [a["action"] for a in timer["actions"]] == ["LogInfo", "Shutdown"]
    assert managed["node"]["lifecycle"] and managed["node"]["autostart"]
    assert sequence["nodes"] == ["/managed"] and sequence["timeout"] == 4
    assert transition["event"] == "state_transition"
    assert transition["handler"] == "OnStateTransition(goal_state='active')"
    assert transition["target"].startswith("LifecycleNode(") and not transition["any_process"]
    assert handler["handler"] == "OnProcessExit"
    assert expect["check"] == "topic" and expect["rate"] == 5.0 and expect["within"] == 9
    assert log["message"] == "now"
    line = DEFERRED.splitlines().index(
        next(x for x in DEFERRED.splitlines() if "TimerAction(" in x)
    )
    assert absolute_origin(timer["origin"]) == {"file": str(launch), "line": line + 1}


MORE = """
from launch import LaunchDescription
from launch.actions import EmitEvent, ExecuteProcess, RegisterEventHandler
from launch.event_handlers import OnProcessIO
from launch.events import matches_action
from launch.events.process import SignalProcess
from mlaunch.actions import Machine

def generate_launch_description():
    here = ExecuteProcess(cmd=['true'], name='here', machine='local', respawn='on-failure',
                          sigterm_timeout='3', sigkill_timeout='0.5')
    return LaunchDescription([
        Machine(name='local', address='127.0.0.1'),
        Machine(name='robot', address='robot-alias', user='ros', ssh_port=2200, timeout=3),
        here,
        ExecuteProcess(cmd=['sleep', '1'], name='far', machine='robot'),
        RegisterEventHandler(OnProcessIO(on_stdout=lambda event: None)),
        EmitEvent(event=SignalProcess(signal_number='SIGUSR1',
                                      process_matcher=matches_action(here))),
    ])
"""


def test_machines_io_handlers_and_events(tmp_path: Path, env: dict[str, str]) -> None:
    launch = tmp_path / "more.launch.py"
    launch.write_text(MORE)
    document = plan_of(str(launch), "--launch-prefix", "env PREFIXED=1", env=env)
    validate(document)
    here, far = processes(document).values()
    assert here["machine"] == {
        "name": "local",
        "address": "127.0.0.1",
        "user": None,
        "ssh_port": None,
        "env_loader": None,
        "timeout": 10.0,
        "local": True,
    }
    assert far["machine"]["name"] == "robot" and far["machine"]["ssh_port"] == 2200
    assert not far["machine"]["local"]
    assert here["launch_prefix"] == ["env", "PREFIXED=1"]
    assert here["argv"][:2] == ["env", "PREFIXED=1"] and here["argv"][2].endswith("true")
    assert here["respawn"]["mode"] == "on-failure"
    assert [r["after"] for r in here["stop"]["ladder"]] == [0.0, 3.0, 3.5]
    assert document["undeclared_arguments"] == {}  # --launch-prefix is not a launch argument
    (handler,) = [s for s in document["steps"] if s["kind"] == "handler"]
    assert handler["event"] == "process_io" and handler["io"] == ["stdout"]
    assert handler["any_process"] and handler["target"] is None
    (emit,) = [s for s in document["steps"] if s["kind"] == "emit"]
    assert emit["event"] == "SignalProcess"


def test_undeclared_arguments_and_warnings(env: dict[str, str]) -> None:
    path = str(LAUNCHES / "examples" / "scoping.launch.py")
    document = plan_of(path, "mode:=real", "wokers:=3", env=env)
    validate(document)
    assert document["undeclared_arguments"] == {"wokers": "3"}
    assert any("'wokers' is not declared" in w for w in document["warnings"])
    args = {a["name"]: a for a in document["arguments"]}
    assert args["mode"]["value"] == "real" and args["mode"]["choices"] == ["sim", "real"]
    assert args["workers"]["value"] == "2" and not args["workers"]["given"]
    timers = [s for s in document["steps"] if s["kind"] == "timer"]
    assert [t["period"] for t in timers] == [1.5, 5.0]
    assert [a["action"] for a in timers[1]["actions"]] == ["Shutdown"]


ODD = """
from launch import LaunchDescription
from launch_ros.actions import Node
from launch_ros.parameter_descriptions import ParameterFile

def generate_launch_description():
    return LaunchDescription([
        Node(package='demo', executable='dump', name='odd',
             parameters=[ParameterFile(FILE), {'when': 'yes'}]),
    ])
"""


def test_values_json_cannot_spell_stay_valid(tmp_path: Path, env: dict[str, str]) -> None:
    """Non-finite doubles, nulls, dates and lists no ROS parameter can hold stay valid JSON."""
    prefix = dump_package(tmp_path)
    params = tmp_path / "odd.yaml"
    params.write_text(
        "/**:\n  ros__parameters:\n    big: .inf\n    small: -.inf\n    nothing: ~\n"
        "    day: 2024-01-02\n    mixed: [1, a]\n    nested:\n      deep: .nan\n"
    )
    launch = tmp_path / "odd.launch.py"
    launch.write_text(ODD.replace("FILE", repr(str(params))))
    document = plan_of(str(launch), env={**env, "AMENT_PREFIX_PATH": str(prefix)})
    validate(document)
    (process,) = processes(document).values()
    shipped, written = process["parameters"]
    assert shipped["path"] == str(params) and not shipped["temporary"]
    typed = {p["name"]: (p["value"], p["type"]) for p in shipped["parameters"]}
    assert typed == {
        "big": (".inf", "double"),
        "small": ("-.inf", "double"),
        "nothing": (None, "not set"),
        "day": ("2024-01-02", "string"),  # PyYAML reads a date; rcl reads text
        "mixed": ([1, "a"], "unsupported"),
        "nested.deep": (".nan", "double"),
    }
    assert shipped["contents"]["/**"]["ros__parameters"]["nested"] == {"deep": ".nan"}
    assert written["temporary"] and written["parameters"][0]["value"] == "yes"


def test_an_unreadable_params_file_is_said(tmp_path: Path, env: dict[str, str]) -> None:
    from mlaunch.resolve.plan_json import params_file_data

    missing = params_file_data(str(tmp_path / "gone.yaml"), "gone.yaml")
    assert missing["contents"] is None and "cannot be read" in missing["error"]
    broken = tmp_path / "broken.yaml"
    broken.write_text("a: [1,\n")
    data = params_file_data(str(broken), str(broken))
    assert data["contents"] is None and data["error"].startswith("not valid YAML")
