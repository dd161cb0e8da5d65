"""``mlaunch convert --to py``: the description as a Python launch file (launch / launch_ros)."""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from typing import Any

from mlaunch.convert.writing import (
    SCOPED_NOTE,
    WIDTH,
    ConversionError,
    Source,
    comments,
    eval_pieces,
    file_header,
    wrap,
)
from mlaunch.ros1.model import (
    MACHINE_FIELDS,
    AnonRef,
    ArgRef,
    CommandRef,
    Cond,
    DeclareArg,
    DirnameRef,
    Dropped,
    EnvRef,
    EvalRef,
    ExecRef,
    FileRef,
    FindRef,
    Group,
    Include,
    Item,
    MachineItem,
    NodeItem,
    Part,
    Process,
    ProcessItem,
    PValue,
    SetArg,
    SetEnv,
    SetParam,
    SetRemap,
    Value,
    Warn,
)


@dataclass
class Py:
    """A Python expression to print: a call, a list, a dict, a tuple, or ready code."""

    kind: str  # "call", "list", "dict", "tuple", "code"
    name: str = ""
    # Py, (key, Py), ("#", comments to wrap) or ("#!", code lines to comment out as they are)
    items: list[Any] = field(default_factory=list)
    keywords: list[tuple[str, Py]] = field(default_factory=list)


def code(text_: str) -> Py:
    return Py("code", name=text_)


def pystr(value: str) -> Py:
    if '"' in value and "'" not in value:
        return code(repr(value))
    return code(json.dumps(value, ensure_ascii=False))


def call(callee: str, /, *args: Py, **keywords: Py | None) -> Py:
    return Py(
        "call", name=callee, items=list(args), keywords=[(k, v) for k, v in keywords.items() if v]
    )


def render(expr: Py, indent: int, used: int = 0) -> str:
    """The expression on one line when it fits (and holds no comment), else spread out.

    ``used``: what precedes it on its line after the indentation (``name=``, ``key: ``).
    """
    flat = _flat(expr)
    if flat is not None and (expr.kind == "code" or indent + used + len(flat) + 1 <= WIDTH):
        return flat
    pad = " " * (indent + 4)
    lines: list[str] = []
    if expr.kind == "call":
        lines += [pad + render(a, indent + 4) + "," for a in expr.items]
        lines += [f"{pad}{k}={render(v, indent + 4, len(k) + 1)}," for k, v in expr.keywords]
        head, tail = expr.name + "(", ")"
    else:
        head, tail = {"list": ("[", "]"), "dict": ("{", "}"), "tuple": ("(", ")")}[expr.kind]
        for item in expr.items:
            if isinstance(item, tuple) and item[0] == "#!":  # code, commented out as it is
                lines += [f"{pad}# {line}" for line in item[1]]
            elif isinstance(item, tuple) and item[0] == "#":
                for comment in item[1]:
                    lines += [f"{pad}# {line}" for line in wrap(comment, WIDTH - len(pad) - 2)]
            elif isinstance(item, tuple):
                key = render(item[0], indent + 4)
                lines.append(f"{pad}{key}: {render(item[1], indent + 4, len(key) + 2)},")
            else:
                lines.append(pad + render(item, indent + 4) + ",")
    return head + "\n" + "\n".join(lines) + "\n" + " " * indent + tail


def _flat(expr: Py) -> str | None:
    if expr.kind == "code":
        return expr.name
    parts: list[str] = []
    for item in expr.items:
        if isinstance(item, tuple) and item[0] in ("#", "#!"):
            return None
        if isinstance(item, tuple):
            key, value = _flat(item[0]), _flat(item[1])
            if key is None or value is None:
                return None
            parts.append(f"{key}: {value}")
        else:
            found = _flat(item)
            if found is None:
                return None
            parts.append(found)
    for key_name, keyword_value in expr.keywords:
        found = _flat(keyword_value)
        if found is None:
            return None
        parts.append(f"{key_name}={found}")
    inner = ", ".join(parts)
    if expr.kind == "call":
        return f"{expr.name}({inner})"
    if expr.kind == "tuple":
        return f"({inner},)" if len(parts) == 1 else f"({inner})"
    return {"list": f"[{inner}]", "dict": f"{{{inner}}}"}[expr.kind]


IMPORTS = {
    "LaunchDescription": "launch",
    "AnyLaunchDescriptionSource": "launch.launch_description_sources",
    "IfCondition": "launch.conditions",
    "UnlessCondition": "launch.conditions",
    "Node": "launch_ros.actions",
    "PushROSNamespace": "launch_ros.actions",
    "SetParameter": "launch_ros.actions",
    "SetRemap": "launch_ros.actions",
    "ParameterValue": "launch_ros.parameter_descriptions",
    "FindPackageShare": "launch_ros.substitutions",
    "ExecutableInPackage": "launch_ros.substitutions",
    "Machine": "mlaunch.actions",
}
for _name in (
    "DeclareLaunchArgument",
    "ExecuteProcess",
    "GroupAction",
    "IncludeLaunchDescription",
    "SetEnvironmentVariable",
    "SetLaunchConfiguration",
    "Shutdown",
):
    IMPORTS[_name] = "launch.actions"
for _name in (
    "AnonName",
    "Command",
    "EnvironmentVariable",
    "FileContent",
    "LaunchConfiguration",
    "PythonExpression",
    "ThisLaunchFileDir",
):
    IMPORTS[_name] = "launch.substitutions"


class PythonWriter:
    """The description as a ``generate_launch_description()`` of launch / launch_ros classes."""

    def __init__(self, source: Source) -> None:
        self.source = source
        self.used: set[str] = {"LaunchDescription"}

    def use(self, callee: str, /, *args: Py, **keywords: Py | None) -> Py:
        self.used.add(callee)
        return call(callee, *args, **keywords)

    def write(self, items: list[Item]) -> str:
        body = render(self.use("LaunchDescription", self.items(items)), 4, len("return "))
        header = file_header(self.source, '"""', '"""')
        imports = _imports(self.used)
        text = (
            f"{header}\n\n{SCOPED_NOTE.format(c='#')}\n{imports}\n\n\n"
            "def generate_launch_description() -> LaunchDescription:\n"
            f"    return {body}\n"
        )
        _check_compiles(text, self.source.path)
        return text

    def items(self, items: list[Item]) -> Py:
        out: list[Any] = []
        for item in items:
            out.append(("#", comments(item, self.source)))
            if isinstance(item, Dropped):
                dropped = render(self.node(item.node), 0).splitlines()
                out.append(("#", ["Where it can run:"]))
                out.append(("#!", dropped))
                continue
            action = self.action(item)
            if action is not None:
                out.append(action)
        return Py("list", items=out)

    def action(self, item: Item) -> Py | None:
        condition = self.condition(item.condition)
        if isinstance(item, Warn):
            return None
        if isinstance(item, DeclareArg):
            default = None if item.default is None else self.value(item.default)
            description = None if item.doc is None else pystr(item.doc)
            return self.use(
                "DeclareLaunchArgument",
                pystr(item.name),
                default_value=default,
                description=description,
                condition=condition,
            )
        if isinstance(item, SetArg):
            return self.use(
                "SetLaunchConfiguration",
                pystr(item.name),
                self.value(item.value),
                condition=condition,
            )
        if isinstance(item, SetParam):
            return self.use(
                "SetParameter",
                name=self.value(item.name),
                value=self.param(item.value),
                condition=condition,
            )
        if isinstance(item, SetRemap):
            return self.use(
                "SetRemap", src=self.value(item.src), dst=self.value(item.dst), condition=condition
            )
        if isinstance(item, SetEnv):
            return self.use(
                "SetEnvironmentVariable",
                self.value(item.name),
                self.value(item.value),
                condition=condition,
            )
        if isinstance(item, Group):
            return self.group(item, condition)
        if isinstance(item, Include):
            return self.include(item, condition)
        if isinstance(item, MachineItem):
            optional = {
                k: self.value(getattr(item, k)) for k, _ in MACHINE_FIELDS if getattr(item, k)
            }
            return self.use(
                "Machine",
                name=self.value(item.name),
                address=self.value(item.address),
                **optional,
                condition=condition,
            )
        if isinstance(item, NodeItem):
            return self.node(item)
        if isinstance(item, ProcessItem):
            return self.use(
                "ExecuteProcess",
                cmd=Py("list", items=[self.value(c) for c in item.cmd]),
                **self.process(item),
            )
        raise TypeError(f"unknown item {item!r}")

    def group(self, item: Group, condition: Py | None) -> Py:
        inner = self.items(item.items)
        if item.namespace is not None:
            inner.items.insert(0, self.use("PushROSNamespace", self.value(item.namespace)))
        scoped = None if item.scoped else code("False")
        return self.use("GroupAction", inner, scoped=scoped, condition=condition)

    def include(self, item: Include, condition: Py | None) -> Py:
        path = self.source.include_path(item)[0]
        source = self.use("AnyLaunchDescriptionSource", self.value(path))
        arguments = None
        if item.arguments:
            pairs = [Py("tuple", items=[pystr(n), self.value(v)]) for n, v in item.arguments]
            arguments = Py("list", items=pairs)
        return self.use(
            "IncludeLaunchDescription", source, launch_arguments=arguments, condition=condition
        )

    def node(self, item: NodeItem) -> Py:
        keywords: dict[str, Py | None] = {
            "package": self.value(item.package),
            "executable": self.value(item.executable),
            "name": None if item.name is None else self.value(item.name),
            "namespace": None if item.namespace is None else self.value(item.namespace),
        }
        if item.arguments:
            keywords["arguments"] = Py("list", items=[self.value(a) for a in item.arguments])
        if item.parameters:
            pairs = [(self.key(n), self.param(v)) for n, v in item.parameters]
            keywords["parameters"] = Py("list", items=[Py("dict", items=pairs)])
        if item.remappings:
            keywords["remappings"] = Py(
                "list",
                items=[
                    Py("tuple", items=[self.value(a), self.value(b)]) for a, b in item.remappings
                ],
            )
        keywords.update(self.process(item))
        return self.use("Node", **keywords)

    def process(self, item: Process) -> dict[str, Py | None]:
        keywords: dict[str, Py | None] = {}
        if item.output is not None:
            keywords["output"] = self.value(item.output)
        if item.respawn is not False:
            keywords["respawn"] = code("True") if item.respawn is True else self.value(item.respawn)
        if item.respawn_delay is not None:
            delay = item.respawn_delay
            keywords["respawn_delay"] = (
                code(repr(delay)) if isinstance(delay, float) else self.value(delay)
            )
        if item.required is True:
            keywords["on_exit"] = self.use("Shutdown")
        elif item.required is not False:
            keywords["required"] = self.value(item.required)
        if item.prefix is not None:
            keywords["prefix"] = self.value(item.prefix)
        if item.env:
            keywords["additional_env"] = Py(
                "dict", items=[(self.key(k), self.value(v)) for k, v in item.env]
            )
        if item.machine is not None:
            keywords["machine"] = self.value(item.machine)
        keywords["condition"] = self.condition(item.condition)
        return keywords

    def condition(self, cond: Cond | None) -> Py | None:
        if cond is None:
            return None
        return self.use("UnlessCondition" if cond.unless else "IfCondition", self.value(cond.value))

    def param(self, value: PValue) -> Py:
        if value.dynamic is None:
            return code(pyliteral(value.literal))
        inner = self.value(value.dynamic)
        if value.vtype is None:
            return inner
        return self.use("ParameterValue", inner, value_type=code(value.vtype.__name__))

    def key(self, value: Value) -> Py:
        if len(value) == 1:
            return self.value(value)
        return Py("tuple", items=[self.part(p) for p in value])

    def value(self, value: Value) -> Py:
        parts = [self.part(p) for p in value] if value else [pystr("")]
        return parts[0] if len(parts) == 1 else Py("list", items=parts)

    def part(self, part: Part) -> Py:
        if isinstance(part, str):
            return pystr(part)
        if isinstance(part, ArgRef):
            return self.use("LaunchConfiguration", pystr(part.name))
        if isinstance(part, FindRef):
            return self.use("FindPackageShare", pystr(part.package))
        if isinstance(part, ExecRef):
            return self.use("ExecutableInPackage", pystr(part.executable), pystr(part.package))
        if isinstance(part, EnvRef):
            default = None if part.default is None else pystr(part.default)
            return self.use("EnvironmentVariable", pystr(part.name), default_value=default)
        if isinstance(part, AnonRef):
            return self.use("AnonName", pystr(part.name))
        if isinstance(part, DirnameRef):
            replaced = self.source.dirname_value()
            if isinstance(replaced[0], str):
                return pystr(replaced[0])
            return self.use("ThisLaunchFileDir")
        if isinstance(part, EvalRef):
            pieces = eval_pieces(part)
            return self.use("PythonExpression", Py("list", items=[self.part(p) for p in pieces]))
        if isinstance(part, CommandRef):
            return self.use("Command", self.value(part.command), on_stderr=pystr("warn"))
        if isinstance(part, FileRef):
            return self.use("FileContent", self.value(part.path))
        raise TypeError(f"unknown substitution {part!r}")


def _check_compiles(text: str, path: str) -> None:
    """A converted file Python cannot read is an error here, not when it is launched."""
    try:
        compile(text, "<converted>", "exec")
    except SyntaxError as e:
        raise ConversionError(
            f"the converted Python would not compile ({e.msg}, line {e.lineno}): the ROS 1 file"
            " nests deeper than one Python expression can (~200 levels); write it as XML or"
            " YAML (--to xml, --to yaml)",
            where=path,
        ) from e


def pyliteral(value: Any) -> str:
    """A parameter literal as Python source, strings in double quotes as ruff writes them."""
    if isinstance(value, str):
        return _flat(pystr(value)) or ""
    if isinstance(value, list):
        return "[" + ", ".join(pyliteral(v) for v in value) + "]"
    return repr(value)


def _imports(used: set[str]) -> str:
    by_module: dict[str, list[str]] = {}
    for name in sorted(used):
        by_module.setdefault(IMPORTS[name], []).append(name)
    lines = []
    for module in sorted(by_module):
        names = ", ".join(by_module[module])
        line = f"from {module} import {names}"
        if len(line) > WIDTH:
            inner = "".join(f"    {n},\n" for n in by_module[module])
            line = f"from {module} import (\n{inner})"
        lines.append(line)
    return "\n".join(lines)
