"""The same system written as .launch.py, .launch.yaml and .launch.xml resolves to equal plans.

Each example in launches/examples/ exists in the three formats. Every variant is resolved with
the same arguments and environment; the plans are reduced to what a run depends on (processes
with argv, cwd, env changes, output, respawn, timeouts, required; logs; timers and what they
resolve to; shutdowns) and must be equal. Params files are compared by content, not by their
temporary paths. This keeps the frontends from drifting apart.
"""

from __future__ import annotations

import os
import re
from pathlib import Path
from typing import Any

import pytest

from mlaunch import readers
from mlaunch.plan.steps import (
    AddHandler,
    Deferred,
    EmitEvent,
    Log,
    Plan,
    ProcessSpec,
    RequestShutdown,
    Spawn,
    StartTimer,
)
from mlaunch.resolve.resolver import LabelCounter, ResolveOptions, resolve, resolve_deferred

EXAMPLES = Path(__file__).resolve().parent.parent / "launches" / "examples"
FORMATS = ("py", "yaml", "xml")
ENV = {
    "PATH": os.environ["PATH"],
    "HOME": "/home/parity",
    "AMENT_PREFIX_PATH": str(EXAMPLES / "prefix"),
}
CASES = [
    ("talker_listener", {}),
    ("talker_listener", {"ns": "r2", "rate": "20", "use_sim": "true", "verbose": "true"}),
    ("scoping", {}),
    ("scoping", {"mode": "real", "workers": "3"}),
    ("include", {}),
    ("include", {"robot": "r2"}),
]
_ORIGIN = re.compile(r"\S+\.launch\.(py|yaml|xml):\d+")


def summarize(name: str, fmt: str, args: dict[str, str], tmp_path: Path) -> dict[str, Any]:
    """Resolve one variant and reduce its plan to comparable data."""
    path = str(EXAMPLES / f"{name}.launch.{fmt}")
    temp_dir = tmp_path / fmt
    temp_dir.mkdir(parents=True)
    options = ResolveOptions(temp_dir=str(temp_dir))
    labels = LabelCounter()
    plan = resolve(
        readers.load(path),
        path=path,
        arguments=args,
        environ=ENV,
        options=options,
        labels=labels,
    )
    return {
        "steps": _steps(plan, str(temp_dir), options, labels),
        "arguments": [
            (a.name, a.default, a.description, a.choices, a.conditional)
            for a in plan.arguments.values()
        ],
        "warnings": [_ORIGIN.sub("<origin>", w) for w in plan.warnings],
    }


def _steps(plan: Plan, temp_dir: str, options: ResolveOptions, labels: LabelCounter) -> list[Any]:
    out: list[Any] = []
    for step in plan.steps:
        if isinstance(step, Spawn) and step.spec is not None:
            out.append(("spawn", _process(step.spec, temp_dir)))
        elif isinstance(step, Log):
            out.append(("log", step.level, step.source, step.message))
        elif isinstance(step, StartTimer) and step.body is not None:
            later = resolve_deferred(step.body, labels=labels, options=options)
            body = _steps(later, temp_dir, options, labels)
            out.append(("timer", step.period, step.cancel_on_shutdown, body))
        elif isinstance(step, RequestShutdown):
            out.append(("shutdown", step.reason))
        elif isinstance(step, AddHandler):
            out.append(("handler", step.kind, step.once, _deferred(step.body)))
        elif isinstance(step, EmitEvent):
            out.append(("event", type(step.event).__name__))
        else:
            out.append((type(step).__name__,))
    return out


def _process(spec: ProcessSpec, temp_dir: str) -> dict[str, Any]:
    return {
        "label": spec.label,
        "argv": [_file_or_text(a, temp_dir) for a in spec.argv],
        "cwd": spec.cwd,
        "env_changes": spec.env_changes,
        "shell": spec.shell,
        "output": spec.output,
        "respawn": spec.respawn,
        "timeouts": (spec.sigterm_timeout, spec.sigkill_timeout),
        "required": spec.required,
        "on_exit": _deferred(spec.on_exit),
        "node": spec.node,
        "standin": spec.standin,
        "temp_files": sorted(_file_or_text(f, temp_dir) for f in spec.temp_files),
    }


def _file_or_text(item: str, temp_dir: str) -> str:
    """A params file mlaunch wrote is compared by its content, not its random name."""
    if item.startswith(temp_dir + os.sep):
        return "<file>\n" + Path(item).read_text()
    return item


def _deferred(deferred: Deferred | None) -> list[str] | None:
    if deferred is None:
        return None
    return [type(e).__name__ for e in deferred.entities]


@pytest.mark.parametrize(("name", "args"), CASES)
def test_three_formats_resolve_to_equal_plans(
    name: str, args: dict[str, str], tmp_path: Path
) -> None:
    plans = {fmt: summarize(name, fmt, args, tmp_path) for fmt in FORMATS}
    assert plans["yaml"] == plans["py"]
    assert plans["xml"] == plans["py"]
    assert plans["py"]["steps"], "an empty plan would make the comparison meaningless"


def _processes(summary: dict[str, Any]) -> list[dict[str, Any]]:
    return [s[1] for s in summary["steps"] if s[0] == "spawn"]


def test_talker_listener_plan_is_the_ros_command_line(tmp_path: Path) -> None:
    summary = summarize("talker_listener", "xml", {"ns": "r2", "verbose": "true"}, tmp_path)
    talker, listener, monitor = _processes(summary)
    prefix = str(EXAMPLES / "prefix" / "lib" / "mlaunch_demo")
    assert talker["label"] == "talker-1" and talker["argv"][:3] == [
        f"{prefix}/talker",
        "--greeting",
        "hello there",
    ]
    argv = talker["argv"]
    assert argv[3:9] == ["--ros-args", "-r", "__node:=talker", "-r", "__ns:=/r2", "-p"]
    files = [argv[i + 1] for i, a in enumerate(argv) if a == "--params-file"]
    # One params file per <param> (ROS 2's layout), nested params flattened to dotted names.
    assert files == [
        "<file>\n/r2/talker:\n  ros__parameters:\n    rate: 5.0\n",
        "<file>\n/r2/talker:\n  ros__parameters:\n    greeting: hello\n",
        "<file>\n/r2/talker:\n  ros__parameters:\n    qos.depth: 10\n    qos.reliable: true\n",
        "<file>\n/r2/talker:\n  ros__parameters:\n    frames:\n    - base\n    - odom\n    - map\n",
    ]
    assert argv[-4:] == ["-r", "/rosout_agg:=rosout_all", "-r", "chatter:=chat"]
    assert talker["respawn"].mode == "always" and talker["env_changes"]["TALKER_MODE"] == "demo"
    assert listener["argv"][1:4] == ["--ros-args", "--log-level", "debug"]
    assert "__ns:=/r2/ears" in listener["argv"] and "chatter:=/r2/chat" in listener["argv"]
    assert monitor["label"] == "monitor-3" and monitor["timeouts"] == (1.0, 1.0)


def test_scoping_plan_keeps_scopes_and_env(tmp_path: Path) -> None:
    summary = summarize("scoping", "yaml", {}, tmp_path)
    logs = [s[3] for s in summary["steps"] if s[0] == "log"]
    assert logs == [
        "inside the group: site=field",
        "after the group: site=lab",
        "isolated: mode=sim site=unset",
    ]
    reporter, simulator = _processes(summary)
    assert reporter["env_changes"]["ZONE"] == "inner"
    assert "ZONE" not in simulator["env_changes"] and simulator["required"]
    timers = [s for s in summary["steps"] if s[0] == "timer"]
    assert [(t[1], t[2]) for t in timers] == [(1.5, True), (5.0, False)]
    (late,) = [s[1] for s in timers[0][3] if s[0] == "spawn"]
    assert late["label"] == "late-3" and "DEMO_PATH" not in late["env_changes"]
    assert timers[1][3] == [("shutdown", "demo over")]


def test_includes_cross_formats_in_every_direction(tmp_path: Path) -> None:
    """YAML includes Python includes XML; XML and Python include YAML and Python."""
    parts = EXAMPLES / "parts"
    for fmt in FORMATS:
        summary = summarize("include", fmt, {"robot": "r2"}, tmp_path / fmt)
        camera, driver_video, driver_acm = _processes(summary)
        assert camera["argv"] == ["sh", "-c", "echo camera $CAMERA on $ROBOT"]  # from YAML
        assert {k: camera["env_changes"][k] for k in ("CAMERA", "ROBOT")} == {
            "CAMERA": "front",
            "ROBOT": "r2",
        }
        assert driver_video["argv"][-1] == "/dev/video_front"  # YAML -> Python
        assert driver_acm["argv"][-1] == "/dev/ttyACM0"  # top level -> Python
        logs = [s[3] for s in summary["steps"] if s[0] == "log"]
        assert logs == [  # Python -> XML, which sees its own directory
            f"logger for driver:/dev/video_front in {parts}",
            "r2 has 1 sensor(s)",
            f"logger for driver:/dev/ttyACM0 in {parts}",
        ]
