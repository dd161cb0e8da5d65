"""Synthetic launch files for the benchmarks, written in Python, YAML and XML from one model.

The same system rendered in the three formats lets a row for each frontend be compared with the
others: same processes, same substitutions, same includes. Values are small templates made of
parts (text, ``$(var)``, ``$(env)``, ``$(dirname)``) so each renderer spells them natively:
``LaunchConfiguration('x')`` in Python, ``$(var x)`` in YAML and XML.
"""

from __future__ import annotations

import json
import os
import stat
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from xml.sax.saxutils import quoteattr

FORMATS = ("py", "yaml", "xml")


# --- the model -----------------------------------------------------------------------------


@dataclass(frozen=True)
class Var:
    """``$(var name)`` / LaunchConfiguration(name)."""

    name: str


@dataclass(frozen=True)
class Env:
    """``$(env NAME default)`` / EnvironmentVariable(NAME, default_value=default)."""

    name: str
    default: str


@dataclass(frozen=True)
class Dirname:
    """``$(dirname)`` / ThisLaunchFileDir()."""


Part = str | Var | Env | Dirname
Value = tuple[Part, ...]


def v(*parts: Part) -> Value:
    """A value: the parts concatenated."""
    return tuple(parts)


@dataclass(frozen=True)
class Arg:
    name: str
    default: Value
    description: str
    choices: tuple[str, ...] = ()


@dataclass(frozen=True)
class Let:
    name: str
    value: Value


@dataclass(frozen=True)
class SetEnv:
    name: str
    value: Value


@dataclass(frozen=True)
class Exec:
    """An executable; each cmd item must perform to one word (no spaces) for the XML/YAML cmd."""

    cmd: tuple[Value, ...]
    name: Value
    output: str | None = None
    condition: Value | None = None
    env: tuple[tuple[str, Value], ...] = ()


@dataclass(frozen=True)
class Include:
    """Another generated file (by stem, same format), with arguments."""

    stem: str
    args: tuple[tuple[str, Value], ...] = ()


@dataclass(frozen=True)
class Group:
    children: tuple[Entity, ...]


Entity = Arg | Let | SetEnv | Exec | Include | Group


@dataclass
class LaunchFile:
    """One file of the model: its stem (``name`` in ``name.launch.py``) and its entities."""

    stem: str
    entities: list[Entity] = field(default_factory=list)


def file_name(stem: str, fmt: str) -> str:
    return f"{stem}.launch.{fmt}"


# --- Python --------------------------------------------------------------------------------

PY_HEADER = """\
from launch import LaunchDescription
from launch.actions import (
    DeclareLaunchArgument,
    ExecuteProcess,
    GroupAction,
    IncludeLaunchDescription,
    SetEnvironmentVariable,
    SetLaunchConfiguration,
)
from launch.conditions import IfCondition
from launch.launch_description_sources import PythonLaunchDescriptionSource
from launch.substitutions import EnvironmentVariable, LaunchConfiguration, ThisLaunchFileDir


def generate_launch_description():
    return LaunchDescription(
        [
"""
PY_FOOTER = """\
        ]
    )
"""


def _py_part(part: Part) -> str:
    if isinstance(part, str):
        return repr(part)
    if isinstance(part, Var):
        return f"LaunchConfiguration({part.name!r})"
    if isinstance(part, Env):
        return f"EnvironmentVariable({part.name!r}, default_value={part.default!r})"
    return "ThisLaunchFileDir()"


def _py_value(value: Value) -> str:
    if len(value) == 1 and isinstance(value[0], str):
        return repr(value[0])
    return "[" + ", ".join(_py_part(p) for p in value) + "]"


def _py_entity(entity: Entity, indent: str) -> str:
    if isinstance(entity, Arg):
        choices = f", choices={list(entity.choices)!r}" if entity.choices else ""
        return (
            f"{indent}DeclareLaunchArgument({entity.name!r}, default_value="
            f"{_py_value(entity.default)}, description={entity.description!r}{choices}),\n"
        )
    if isinstance(entity, Let):
        return f"{indent}SetLaunchConfiguration({entity.name!r}, {_py_value(entity.value)}),\n"
    if isinstance(entity, SetEnv):
        return f"{indent}SetEnvironmentVariable({entity.name!r}, {_py_value(entity.value)}),\n"
    if isinstance(entity, Exec):
        words = [f"cmd=[{', '.join(_py_value(c) for c in entity.cmd)}]"]
        words.append(f"name={_py_value(entity.name)}")
        if entity.output:
            words.append(f"output={entity.output!r}")
        if entity.condition is not None:
            words.append(f"condition=IfCondition({_py_value(entity.condition)})")
        if entity.env:
            pairs = ", ".join(f"{k!r}: {_py_value(val)}" for k, val in entity.env)
            words.append(f"additional_env={{{pairs}}}")
        return f"{indent}ExecuteProcess({', '.join(words)}),\n"
    if isinstance(entity, Include):
        source = f"PythonLaunchDescriptionSource([ThisLaunchFileDir(), {'/' + file_name(entity.stem, 'py')!r}])"
        args = ", ".join(f"({k!r}, {_py_value(val)})" for k, val in entity.args)
        return f"{indent}IncludeLaunchDescription({source}, launch_arguments=[{args}]),\n"
    inner = "".join(_py_entity(child, indent + "        ") for child in entity.children)
    return f"{indent}GroupAction(\n{indent}    [\n{inner}{indent}    ]\n{indent}),\n"


def render_python(launch: LaunchFile) -> str:
    body = "".join(_py_entity(e, " " * 12) for e in launch.entities)
    return PY_HEADER + body + PY_FOOTER


# --- XML and YAML share the $(...) spelling -------------------------------------------------


def _frontend_part(part: Part) -> str:
    if isinstance(part, str):
        if "$" in part or " " in part:
            raise ValueError(f"benchmark text part {part!r} must not contain '$' or spaces")
        return part
    if isinstance(part, Var):
        return f"$(var {part.name})"
    if isinstance(part, Env):
        return f"$(env {part.name} {part.default})"
    return "$(dirname)"


def frontend_value(value: Value) -> str:
    return "".join(_frontend_part(p) for p in value)


def _frontend_cmd(entity: Exec) -> str:
    return " ".join(frontend_value(c) for c in entity.cmd)


def _xml_entity(entity: Entity, indent: str) -> str:
    q = quoteattr
    if isinstance(entity, Arg):
        head = (
            f"{indent}<arg name={q(entity.name)} default={q(frontend_value(entity.default))}"
            f" description={q(entity.description)}"
        )
        if not entity.choices:
            return head + "/>\n"
        choices = "".join(f"{indent}  <choice value={q(c)}/>\n" for c in entity.choices)
        return f"{head}>\n{choices}{indent}</arg>\n"
    if isinstance(entity, Let):
        return f"{indent}<let name={q(entity.name)} value={q(frontend_value(entity.value))}/>\n"
    if isinstance(entity, SetEnv):
        value = q(frontend_value(entity.value))
        return f"{indent}<set_env name={q(entity.name)} value={value}/>\n"
    if isinstance(entity, Exec):
        attrs = f" cmd={q(_frontend_cmd(entity))} name={q(frontend_value(entity.name))}"
        if entity.output:
            attrs += f" output={q(entity.output)}"
        if entity.condition is not None:
            attrs += f" if={q(frontend_value(entity.condition))}"
        if not entity.env:
            return f"{indent}<executable{attrs}/>\n"
        envs = "".join(
            f"{indent}  <env name={q(k)} value={q(frontend_value(val))}/>\n"
            for k, val in entity.env
        )
        return f"{indent}<executable{attrs}>\n{envs}{indent}</executable>\n"
    if isinstance(entity, Include):
        path = q("$(dirname)/" + file_name(entity.stem, "xml"))
        args = "".join(
            f"{indent}  <arg name={q(k)} value={q(frontend_value(val))}/>\n"
            for k, val in entity.args
        )
        return f"{indent}<include file={path}>\n{args}{indent}</include>\n"
    inner = "".join(_xml_entity(child, indent + "  ") for child in entity.children)
    return f"{indent}<group>\n{inner}{indent}</group>\n"


def render_xml(launch: LaunchFile) -> str:
    body = "".join(_xml_entity(e, "  ") for e in launch.entities)
    return f'<?xml version="1.0"?>\n<launch>\n{body}</launch>\n'


def _yaml_scalar(text: str) -> str:
    return json.dumps(text)  # a JSON string is a valid YAML double-quoted scalar


def _yaml_entity(entity: Entity, indent: str) -> str:
    s = _yaml_scalar
    if isinstance(entity, Arg):
        out = (
            f"{indent}- arg:\n{indent}    name: {s(entity.name)}\n"
            f"{indent}    default: {s(frontend_value(entity.default))}\n"
            f"{indent}    description: {s(entity.description)}\n"
        )
        if entity.choices:
            out += f"{indent}    choice:\n"
            out += "".join(f"{indent}    - value: {s(c)}\n" for c in entity.choices)
        return out
    if isinstance(entity, Let):
        value = s(frontend_value(entity.value))
        return f"{indent}- let: {{name: {s(entity.name)}, value: {value}}}\n"
    if isinstance(entity, SetEnv):
        value = s(frontend_value(entity.value))
        return f"{indent}- set_env: {{name: {s(entity.name)}, value: {value}}}\n"
    if isinstance(entity, Exec):
        out = f"{indent}- executable:\n{indent}    cmd: {s(_frontend_cmd(entity))}\n"
        out += f"{indent}    name: {s(frontend_value(entity.name))}\n"
        if entity.output:
            out += f"{indent}    output: {s(entity.output)}\n"
        if entity.condition is not None:
            out += f"{indent}    if: {s(frontend_value(entity.condition))}\n"
        if entity.env:
            out += f"{indent}    env:\n"
            out += "".join(
                f"{indent}    - {{name: {s(k)}, value: {s(frontend_value(val))}}}\n"
                for k, val in entity.env
            )
        return out
    if isinstance(entity, Include):
        out = f"{indent}- include:\n"
        out += f"{indent}    file: {s('$(dirname)/' + file_name(entity.stem, 'yaml'))}\n"
        if entity.args:
            out += f"{indent}    arg:\n"
            out += "".join(
                f"{indent}    - {{name: {s(k)}, value: {s(frontend_value(val))}}}\n"
                for k, val in entity.args
            )
        return out
    inner = "".join(_yaml_entity(child, indent + "      ") for child in entity.children)
    return f"{indent}- group:\n{indent}    children:\n{inner}"


def render_yaml(launch: LaunchFile) -> str:
    body = "".join(_yaml_entity(e, "") for e in launch.entities)
    return "launch:\n" + body


RENDERERS = {"py": render_python, "yaml": render_yaml, "xml": render_xml}


def write(files: Sequence[LaunchFile], fmt: str, directory: Path) -> Path:
    """Write every file of a model in one format; the path of the first (the top) file."""
    if fmt not in RENDERERS:
        raise ValueError(f"unknown launch format {fmt!r}; valid: {', '.join(FORMATS)}")
    directory.mkdir(parents=True, exist_ok=True)
    for launch in files:
        (directory / file_name(launch.stem, fmt)).write_text(RENDERERS[fmt](launch))
    return directory / file_name(files[0].stem, fmt)


# --- the benchmark systems -----------------------------------------------------------------

READY_SCRIPT = """\
#!/bin/sh
# Benchmark child. Opens the probe FIFO as fd 3 (held open by 'sleep' after the exec: the
# harness sees EOF when every child is gone), says it is running with one line, then sleeps.
# sh builtins only: no fork beyond the launcher's own.
exec 3>>"$1"
echo r >&3
exec sleep 100000
"""

EMIT_SCRIPT = """\
#!/bin/sh
# Benchmark child: prints $1 lines as fast as the pipe takes them (seq is C, buffered).
exec seq -f "benchline %g: the quick brown fox jumps over the lazy dog; frame ok" "$1"
"""

EMIT_TOKEN = b"benchline "


@dataclass(frozen=True)
class ChildScripts:
    """Paths of the two child programs the benchmarks start."""

    ready: Path
    emit: Path


def write_child_scripts(directory: Path) -> ChildScripts:
    directory.mkdir(parents=True, exist_ok=True)
    scripts = ChildScripts(ready=directory / "ready_child.sh", emit=directory / "emit_child.sh")
    for path, text in ((scripts.ready, READY_SCRIPT), (scripts.emit, EMIT_SCRIPT)):
        path.write_text(text)
        os.chmod(path, os.stat(path).st_mode | stat.S_IXUSR | stat.S_IXGRP | stat.S_IXOTH)
    return scripts


def many_children(stem: str, n: int, argv: Sequence[str], output: str | None = None) -> LaunchFile:
    """N executables with the same fixed argv, named c0..c{n-1}."""
    cmd = tuple(v(word) for word in argv)
    return LaunchFile(stem, [Exec(cmd, v(f"c{i}"), output=output) for i in range(n)])


LEVELS = 3  # includes below the top file
FANOUT = 2  # includes per file
EXECS_PER_FILE = 4
TOP_ARGS = 20


def _top_args() -> list[Entity]:
    args: list[Entity] = [
        Arg("robot", v("bot"), "Robot name prefix"),
        Arg("mode", v("fast"), "Planner mode", ("fast", "slow", "careful")),
        Arg("enable", v("true"), "Start the workers"),
        Arg("rate", v("10"), "Worker rate [Hz]"),
    ]
    for i in range(len(args), TOP_ARGS - 2):  # + index and frame_prefix below
        default = v("value", str(i)) if i % 3 else v(Var("robot"), "_", str(i))
        args.append(Arg(f"opt{i:02d}", default, f"Synthetic option {i} for the benchmark"))
    return args


def _level_args() -> list[Entity]:
    return [
        Arg("robot", v("bot"), "Robot name"),
        Arg("index", v("0"), "Instance index"),
        Arg("mode", v("fast"), "Planner mode", ("fast", "slow", "careful")),
        Arg("enable", v("true"), "Start the workers"),
        Arg("rate", v("10"), "Worker rate [Hz]"),
        Arg("frame_prefix", v(Var("robot"), "_", Var("index")), "TF prefix"),
    ]


def _level_body(level: int) -> list[Entity]:
    """What every file of the big system does: lets, an env change, a group of processes."""
    body: list[Entity] = [
        Let("frame", v(Var("frame_prefix"), "_base_link")),
        Let("topic", v("/", Var("robot"), "/", Var("index"), "/scan")),
        SetEnv("BENCH_LEVEL", v(str(level), "_", Var("index"))),
    ]
    execs: list[Entity] = []
    for k in range(EXECS_PER_FILE):
        cmd = (
            v("echo"),
            v("--robot=", Var("robot"), "_", Var("index")),
            v("--mode=", Var("mode")),
            v("--rate=", Var("rate")),
            v("--frame=", Var("frame")),
            v("--topic=", Var("topic")),
            v("--home=", Env("HOME", "/root")),
            v("--level=", Env("BENCH_LEVEL", "none")),
            v("--config=", Dirname(), "/config/", Var("robot"), "_", str(k), ".yaml"),
            v("--worker=", str(k)),
        )
        execs.append(
            Exec(
                cmd,
                v("w", str(level), "_", Var("index"), "_", str(k)),
                output="screen",
                condition=v(Var("enable")),
                env=(("BENCH_ROBOT", v(Var("robot"))), ("BENCH_FRAME", v(Var("frame")))),
            )
        )
    body.append(Group(tuple(execs)))
    if level < LEVELS:
        for j in range(FANOUT):
            args = (
                ("robot", v(Var("robot"))),
                ("index", v(Var("index"), str(j))),
                ("mode", v(Var("mode"))),
                ("enable", v(Var("enable"))),
                ("rate", v(Var("rate"))),
            )
            # In a group, as ROS 2 users scope includes: the arguments stay with this include.
            body.append(Group((Include(f"big_l{level + 1}", args),)))
    return body


def big_system() -> list[LaunchFile]:
    """20 top-level arguments, 3 levels of includes (fan-out 2: 15 file instances), 60
    processes with ~20 substitutions each: about 1,500 substitutions performed per resolve."""
    top = LaunchFile("big", [*_top_args(), Arg("index", v("0"), "Instance index")])
    top.entities.append(Arg("frame_prefix", v(Var("robot"), "_", Var("index")), "TF prefix"))
    top.entities.extend(_level_body(0))
    files = [top]
    for level in range(1, LEVELS + 1):
        files.append(LaunchFile(f"big_l{level}", [*_level_args(), *_level_body(level)]))
    return files


NODE_LAUNCH = """\
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node, PushROSNamespace, SetParameter


def generate_launch_description():
    return LaunchDescription([
        DeclareLaunchArgument("ns", default_value="robot"),
        PushROSNamespace(LaunchConfiguration("ns")),
        SetParameter("use_sim_time", True),
        Node(package="bench_pkg", executable="ready", name="ready", namespace="sub",
             arguments=[{fifo!r}], remappings=[("chatter", "out")], output="screen"),
    ])
"""


def write_node_launch(directory: Path, child: Path, fifo: Path) -> tuple[Path, Path]:
    """A one-Node launch and the ament prefix holding its package: (launch file, prefix).

    The package ``bench_pkg`` is installed as colcon would lay it out (resource index marker,
    share folder, ``lib/bench_pkg/ready``), its executable a link to the ready child, so the
    figure covers the package lookup and launch_ros's command line (name, namespace, remaps,
    global parameters) on top of what an ExecuteProcess launch does.
    """
    prefix = directory / "install"
    marker = prefix / "share" / "ament_index" / "resource_index" / "packages" / "bench_pkg"
    marker.parent.mkdir(parents=True, exist_ok=True)
    marker.write_text("")
    (prefix / "share" / "bench_pkg").mkdir(parents=True, exist_ok=True)
    lib = prefix / "lib" / "bench_pkg"
    lib.mkdir(parents=True, exist_ok=True)
    ready = lib / "ready"
    if not ready.exists():
        ready.symlink_to(child)
    path = directory / "node.launch.py"
    path.write_text(NODE_LAUNCH.format(fifo=str(fifo)))
    return path, prefix
