"""``--print --format json``: the resolved plan as data, for tools and CI.

The document follows the JSON Schema ``mlaunch/schemas/plan-1.json`` (``docs/plan-json.md``
says what each field means). It is built from the same Plan the text ``--print`` describes and
the supervisor runs; nothing here resolves anything again. What only run time knows (the bodies
of timers and event handlers, a process's on-exit actions) is listed as the actions written
there, unresolved.

Stable from run to run: keys are always present (null where a value does not apply), lists
keep plan order, environment changes are sorted, and the parameter files mlaunch writes into
the run's temporary folder (random names, removed at the end of the run) are named
``<run-temp>/1``, ``<run-temp>/2`` ... in plan order, with their parsed contents alongside.
Only ``--print`` imports this module (json and yaml stay off a launch's start-up path).
"""

from __future__ import annotations

import json
import os
import signal

from mlaunch.plan.steps import (
    AddHandler,
    Deferred,
    Elsewhere,
    EmitEvent,
    Log,
    Plan,
    ProcessSpec,
    RemoveHandler,
    RequestShutdown,
    Spawn,
    StartTimer,
    Step,
)
from mlaunch.plan.text import json_safe, rel
from mlaunch.resolve.describe import _flatten

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING
if TYPE_CHECKING:
    from collections.abc import Callable, Mapping, Sequence
    from typing import Any

    from mlaunch.plan.machine import MachineSpec
    from mlaunch.plan.steps import ArgumentInfo, NodeInfo

SCHEMA_ID = "mlaunch-plan/1"
ARGUMENTS_SCHEMA_ID = "mlaunch-arguments/1"
TEMP_PLACEHOLDER = "<run-temp>"
# rcl's command line: options that take the next token (mlaunch reads -r, -p and --params-file).
_ROS_VALUE_OPTIONS = frozenset(
    {"-r", "--remap", "-p", "--param", "--params-file", "--log-level", "-e", "--enclave"}
)
_SPECIAL_REMAPS = ("__node:=", "__ns:=")


def plan_json(
    plan: Plan, path: str, given: Mapping[str, str], test: dict[str, Any] | None = None
) -> str:
    """The plan document as JSON text (two-space indent, one trailing newline)."""
    document = plan_document(plan, path, given, test)
    return json.dumps(document, indent=2, ensure_ascii=False, allow_nan=False) + "\n"


def arguments_json(infos: Sequence[ArgumentInfo], path: str, given: Mapping[str, str]) -> str:
    """``--show-args --format json``: every argument the file and the files it includes by a
    path known before running declare (mlaunch.resolve.resolver.collect_arguments). Nothing is
    resolved: ``value`` is the command line's or null; ``conditional``: under a condition or
    in a timer."""
    arguments = [{**_argument(info, given), "value": given.get(info.name)} for info in infos]
    document = {
        "schema": ARGUMENTS_SCHEMA_ID,
        "launch_file": rel(path),
        "arguments": arguments,
    }
    return json.dumps(document, indent=2, ensure_ascii=False) + "\n"


def plan_document(
    plan: Plan, path: str, given: Mapping[str, str], test: dict[str, Any] | None = None
) -> dict[str, Any]:
    """The plan as plain data: ``given`` is the command line's ``name:=value`` arguments,
    ``test`` what ``mlaunch test`` would check (commands.smoke), None for ``mlaunch FILE``."""
    from mlaunch.resolve.resolver import BUILTIN_CONFIGURATIONS  # --launch-prefix's, not the file's

    writer = _Writer(plan.temp_dir)
    undeclared = {
        k: v
        for k, v in given.items()
        if k not in plan.arguments and k not in BUILTIN_CONFIGURATIONS
    }
    return {
        "schema": SCHEMA_ID,
        "launch_file": rel(path),
        "arguments": [_argument(info, given) for info in plan.arguments.values()],
        "undeclared_arguments": undeclared,
        "warnings": list(plan.warnings),
        "steps": [writer.step(step) for step in plan.steps],
        "test": test,
    }


def origin_data(origin: str) -> dict[str, Any] | None:
    """``file:line`` as ``{"file": ..., "line": ...}`` (file relative to the current folder as
    the text shows it), None when unknown."""
    if not origin:
        return None
    file, sep, line = origin.rpartition(":")
    if not sep or not line.isdigit():
        return {"file": rel(origin), "line": None}
    return {"file": rel(file), "line": int(line)}


def _argument(info: ArgumentInfo, given: Mapping[str, str]) -> dict[str, Any]:
    return {
        "name": info.name,
        "value": info.value,
        "given": info.name in given,
        "default": info.default,
        "description": info.description,
        "choices": None if info.choices is None else list(info.choices),
        "conditional": info.conditional,
        "origin": origin_data(info.origin),
    }


class _Writer:
    """Turns steps into data; numbers the run's temporary files in the order it meets them."""

    def __init__(self, temp_dir: str | None) -> None:
        self.temp_dir = temp_dir.rstrip(os.sep) + os.sep if temp_dir else None
        self.temp_names: dict[str, str] = {}
        self.kinds: dict[type, Callable[[Any], dict[str, Any]]] = {
            Spawn: self._spawn,
            Log: _log,
            StartTimer: _timer,
            AddHandler: _handler,
            RemoveHandler: _remove_handler,
            RequestShutdown: _shutdown,
            EmitEvent: _emit,
            Elsewhere: _elsewhere,
        }

    def step(self, step: Step) -> dict[str, Any]:
        kind = self.kinds.get(type(step))
        if kind is not None:
            return kind(step)
        # Steps of upper layers (composable node loads, lifecycle sequences, expectations)
        # describe themselves, as they do for the text --print.
        describe = getattr(step, "describe_data", None)
        if describe is None:
            raise TypeError(f"plan step {type(step).__name__} cannot describe itself as data")
        data: dict[str, Any] = describe()
        return {"kind": data.pop("kind"), "origin": origin_data(step.origin), **data}

    def stable(self, item: str) -> str:
        """``item`` with a path in the run's temporary folder replaced by its stable name."""
        if self.temp_dir is None or not item.startswith(self.temp_dir):
            return item
        name = self.temp_names.get(item)
        if name is None:
            name = self.temp_names[item] = f"{TEMP_PLACEHOLDER}/{len(self.temp_names) + 1}"
        return name

    def _spawn(self, step: Spawn) -> dict[str, Any]:
        if step.spec is None:
            raise TypeError("a Spawn step without a process")
        return self.process(step.spec)

    def process(self, spec: ProcessSpec) -> dict[str, Any]:
        argv = [self.stable(item) for item in spec.argv]
        ros = _RosArguments(spec.argv, self) if not spec.shell else None
        return {
            "kind": "process",
            "label": spec.label,
            "origin": origin_data(spec.origin),
            "start": "launch",
            "argv": argv,
            "shell": spec.shell,
            "launch_prefix": list(spec.launch_prefix),
            "cwd": spec.cwd,
            "env": _env(spec.env_changes),
            "output": spec.output,
            "emulate_tty": spec.emulate_tty,
            "node": _node(spec.node),
            "parameters": [] if ros is None else ros.parameters,
            "remaps": [] if ros is None else ros.remaps,
            "respawn": _respawn(spec),
            "stop": _stop(spec),
            "required": spec.required,
            "on_exit": None if spec.on_exit is None else deferred_data(spec.on_exit),
            "standin": spec.standin,
            "machine": _machine(spec.machine),
        }


def _env(changes: Mapping[str, str | None]) -> dict[str, Any]:
    return {
        "set": {k: v for k, v in sorted(changes.items()) if v is not None},
        "unset": sorted(k for k, v in changes.items() if v is None),
    }


def _node(node: NodeInfo | None) -> dict[str, Any] | None:
    if node is None:
        return None
    return {
        **_attributes(node, "name", "namespace"),
        "full_name": node.fully_qualified_name,
        **_attributes(node, "package", "executable", "lifecycle", "autostart"),
    }


def _attributes(record: Any, *names: str) -> dict[str, Any]:
    return {name: getattr(record, name) for name in names}


def _respawn(spec: ProcessSpec) -> dict[str, Any]:
    policy = spec.respawn
    return {
        "mode": policy.mode,
        "delay": policy.delay,
        "max_retries": None if policy.max_retries < 0 else policy.max_retries,
        "backoff": policy.backoff,
        "max_delay": policy.max_delay,
    }


def _stop(spec: ProcessSpec) -> dict[str, Any]:
    """The stop ladder (mlaunch.engine.ladder): each signal to the process group, with the seconds
    since the stop began after which it is sent if the group still lives."""
    term, kill = spec.sigterm_timeout, spec.sigkill_timeout
    return {
        "sigterm_timeout": term,
        "sigkill_timeout": kill,
        "ladder": [
            {"signal": signal.SIGINT.name, "after": 0.0},
            {"signal": signal.SIGTERM.name, "after": term},
            {"signal": signal.SIGKILL.name, "after": term + kill},
        ],
    }


def _elsewhere(step: Elsewhere) -> dict[str, Any]:
    return {
        "kind": "elsewhere",
        "origin": origin_data(step.origin),
        "share": step.share or None,
        "label": None if step.spec is None else step.spec.label,
        "container": step.container,
    }


def _machine(machine: MachineSpec | None) -> dict[str, Any] | None:
    if machine is None:
        return None
    fields = ("name", "address", "user", "ssh_port", "env_loader", "timeout", "local")
    return _attributes(machine, *fields)


# --- what run time decides ------------------------------------------------------------------------


def deferred_data(body: Deferred) -> dict[str, Any]:
    """A timer's, handler's or on-exit's body as written: its actions (unresolved: they are
    resolved when the trigger fires) or the function that returns them."""
    callback = None
    if body.callback is not None:
        callback = getattr(body.callback, "__qualname__", None) or repr(body.callback)
    return {"actions": [_entity(e) for e in body.entities], "callback": callback}


def _entity(entity: Any) -> dict[str, Any]:
    return {
        "action": type(entity).__name__,
        "summary": _summary(entity),
        "origin": origin_data(getattr(entity, "origin", "") or ""),
    }


def _summary(thing: Any) -> str:
    """An action or handler as written (its describe_short), else its class name."""
    describe = getattr(thing, "describe_short", None)
    return str(describe()) if describe is not None else type(thing).__name__


def _log(step: Log) -> dict[str, Any]:
    fields = _attributes(step, "level", "source", "message")
    return {"kind": "log", "origin": origin_data(step.origin), **fields}


def _timer(step: StartTimer) -> dict[str, Any]:
    body = step.body
    return {
        "kind": "timer",
        "origin": origin_data(step.origin),
        "start": "deferred",
        "period": step.period,
        "cancel_on_shutdown": step.cancel_on_shutdown,
        **(deferred_data(body) if body is not None else {"actions": [], "callback": None}),
    }


def _handler(step: AddHandler) -> dict[str, Any]:
    target = getattr(step.handler, "target_action", None)
    if target is None:
        described = None
    elif hasattr(target, "describe_short"):
        described = target.describe_short()
    else:  # a predicate over actions (launch's matcher form)
        described = getattr(target, "__qualname__", None) or repr(target)
    body = step.body
    return {
        "kind": "handler",
        "origin": origin_data(step.origin),
        "start": "deferred",
        "event": step.kind,
        "handler": _summary(step.handler) if step.handler is not None else None,
        "target": described,
        "any_process": step.matcher is None,
        "once": step.once,
        "io": sorted(step.io_callbacks),
        **(deferred_data(body) if body is not None else {"actions": [], "callback": None}),
    }


def _remove_handler(step: RemoveHandler) -> dict[str, Any]:
    handler = step.handler
    return {
        "kind": "remove_handler",
        "origin": origin_data(step.origin),
        "event": getattr(handler, "kind", None),
    }


def _shutdown(step: RequestShutdown) -> dict[str, Any]:
    return {"kind": "shutdown", "origin": origin_data(step.origin), "reason": step.reason}


def _emit(step: EmitEvent) -> dict[str, Any]:
    return {"kind": "emit", "origin": origin_data(step.origin), "event": type(step.event).__name__}


# --- what a node's command line gives it --------------------------------------------------------


class _RosArguments:
    """The parameters and remaps in a process's ROS arguments (each ``--ros-args`` section up to
    ``--``), in order: exactly what the node reads, whichever action put them there."""

    def __init__(self, argv: tuple[str, ...], writer: _Writer) -> None:
        self.parameters: list[dict[str, Any]] = []
        self.remaps: list[dict[str, Any]] = []
        inside = False
        items = iter(argv)
        for item in items:
            if item == "--ros-args":
                inside = True
            elif item == "--":
                inside = False
            elif inside and item in _ROS_VALUE_OPTIONS:
                value = next(items, None)
                if value is not None:
                    self._option(item, value, writer)

    def _option(self, option: str, value: str, writer: _Writer) -> None:
        if option in ("-r", "--remap"):
            if not value.startswith(_SPECIAL_REMAPS):  # the node's name and namespace
                source, _, target = value.partition(":=")
                self.remaps.append({"from": source, "to": target})
        elif option in ("-p", "--param"):
            name, _, text = value.partition(":=")
            self.parameters.append({"kind": "value", **_typed(name, _yaml_value(text))})
        elif option == "--params-file":
            self.parameters.append(params_file_data(value, writer.stable(value)))


# The largest params file of the user's whose contents and parameters the plan shows: real ones
# are well under 100 KiB; 1,000,000 keys (21 MB) took 64-73 s and 1.67 GB to read and write as
# JSON. The files mlaunch writes for a run are always shown (a 48 MB URDF is one value).
PARAMS_FILE_SHOWN = 2**20


def params_file_data(path: str, shown: str) -> dict[str, Any]:
    """A params file: its path as shown, whether mlaunch wrote it for this run, its parsed
    contents and the parameters it gives, per node key (``/**`` or a full name)."""
    import yaml

    entry: dict[str, Any] = {
        "kind": "file",
        "path": shown,
        "temporary": shown != path,
        "contents": None,
        "parameters": [],
        "error": None,
    }
    try:
        from mlaunch.plan.yamldata import load as load_yaml

        with open(path, encoding="utf-8") as f:
            size = os.fstat(f.fileno()).st_size
            if size > PARAMS_FILE_SHOWN and shown == path:  # the user's; mlaunch's are shown
                entry["error"] = (
                    f"not read: {size / 2**20:.1f} MiB, more than the"
                    f" {PARAMS_FILE_SHOWN // 2**20} MiB --print --format json reads of a params"
                    " file (the node reads it whole)"
                )
                return entry
            contents = load_yaml(f.read(), path)
    except OSError as e:
        entry["error"] = f"cannot be read: {e.strerror}"
        return entry
    except yaml.YAMLError as e:
        entry["error"] = f"not valid YAML: {str(e).splitlines()[0]}"
        return entry
    entry["contents"] = json_safe(contents)
    if isinstance(contents, dict):
        for node, section in _sections(contents, []):
            for name, value in _flatten(section):
                entry["parameters"].append({"node": node, **_typed(name, value)})
    return entry


def _sections(data: dict[Any, Any], keys: list[str]) -> list[tuple[str, dict[Any, Any]]]:
    """``(node key, ros__parameters)`` of a params file, nested namespaces joined with '/'."""
    out: list[tuple[str, dict[Any, Any]]] = []
    for key, value in data.items():
        if key == "ros__parameters" and isinstance(value, dict):
            out.append(("/" + "/".join(k.strip("/") for k in keys), value))
        elif isinstance(value, dict):
            out.extend(_sections(value, [*keys, str(key)]))
    return out


def _yaml_value(text: str) -> Any:
    """A ``-p name:=value`` value as rcl reads it: YAML, else the text itself."""
    import yaml

    try:
        from mlaunch.plan.yamldata import load as load_yaml

        return load_yaml(text, "a -p name:=value") if text else ""
    except yaml.YAMLError:
        return text


def _typed(name: str, value: Any) -> dict[str, Any]:
    """One parameter: its name, its value as JSON data and its ROS type."""
    value = _as_rcl_reads(value)
    return {"name": name, "value": json_safe(value), "type": type_name(value)}


def _as_rcl_reads(value: Any) -> Any:
    """PyYAML's dates and times as the text they are to rcl, which knows no such type."""
    if isinstance(value, list):
        return [_as_rcl_reads(v) for v in value]
    if value is None or isinstance(value, (bool, int, float, str, dict, tuple)):
        return value
    return str(value)


def type_name(value: Any) -> str:
    """The ROS parameter type of a value (rcl_interfaces/ParameterType's names), or
    ``unsupported`` for what no parameter can hold (a map in a list, a mixed list)."""
    from mlaunch.launch_ros.load_request import TYPE_NAMES, parameter_type
    from mlaunch.plan.errors import SubstitutionFailure

    try:
        return TYPE_NAMES[parameter_type("", value)]
    except SubstitutionFailure:
        return "unsupported"
