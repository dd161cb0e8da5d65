"""--print and --show-args: the resolved plan and the arguments, as text a person reads."""

from __future__ import annotations

import os
import shlex
from collections.abc import Sequence

from mlaunch.launch.events.execution_complete import ExecutionComplete
from mlaunch.plan.steps import (
    AddHandler,
    ArgumentInfo,
    Elsewhere,
    EmitEvent,
    Log,
    Plan,
    ProcessSpec,
    RemoveHandler,
    RequestShutdown,
    Spawn,
    StartTimer,
)
from mlaunch.plan.text import rel, shorten, value_text

LONG_VALUE = 160

HANDLER_WORDS = {
    "process_start": "when {target} starts",
    "process_exit": "when {target} exits",
    "process_io": "on output of {target}",
    "shutdown": "at shutdown",
    "state_transition": "on a lifecycle transition of {target}",
}


def describe_plan(plan: Plan, path: str) -> str:
    processes = plan.processes()
    out = [f"Plan for {rel(path)}: {len(processes)} process(es) at start", ""]
    for warning in plan.warnings:
        out.append(f"warning: {warning}")
    if plan.warnings:
        out.append("")
    for step in plan.steps:
        if isinstance(step, Spawn) and step.spec is not None:
            out.extend(describe_process(step.spec, plan.temp_dir))
        elif isinstance(step, Log):
            out.append(f"log [{step.level}] {step.message}")
        elif isinstance(step, StartTimer) and step.body is not None:
            out.append(
                f"timer after {step.period:g} s: {step.body.describe()}   ({rel(step.origin)})"
            )
        elif isinstance(step, AddHandler) and step.body is not None:
            target = "any process" if step.matcher is None else "its target"
            target_action = getattr(step.handler, "target_action", None)
            if target_action is not None and hasattr(target_action, "describe_short"):
                target = target_action.describe_short()
            when = HANDLER_WORDS.get(step.kind, step.kind).format(target=target)
            what = (
                step.body.describe() if (step.body.entities or step.body.callback) else "callbacks"
            )
            out.append(f"handler {when}: {what}   ({rel(step.origin)})")
        elif isinstance(step, RemoveHandler):
            out.append("remove a handler")
        elif isinstance(step, RequestShutdown):
            out.append(f"shutdown: {step.reason}")
        elif isinstance(step, EmitEvent) and not isinstance(step.event, ExecutionComplete):
            # (an action's completion, emitted for OnExecutionComplete handlers, goes unsaid)
            out.append(f"emit {type(step.event).__name__}")
        elif isinstance(step, Elsewhere):
            out.append(f"elsewhere: {step.describe()}   ({rel(step.origin)})")
        elif hasattr(step, "describe_lines"):
            # Steps of extensions (composable node loads) describe themselves.
            out.extend(step.describe_lines())
            out.append("")
        out.append("") if isinstance(step, Spawn) else None
    return "\n".join(out).rstrip() + "\n"


def describe_process(spec: ProcessSpec, temp_dir: str | None) -> list[str]:
    head = spec.label
    if spec.standin:
        head += f"   (stand-in for {spec.standin})"
    lines = [head + (f"   {rel(spec.origin)}" if spec.origin else "")]
    made = _made_files(spec.argv, temp_dir)
    argv = " ".join(spec.argv) if spec.shell else shlex.join(spec.argv)
    for path, name in made.items():  # (a temporary path needs no shell quotes)
        argv = argv.replace(path, name)
    lines.append(f"  argv:    {shorten(argv, 400)}" + ("   [via /bin/sh -c]" if spec.shell else ""))
    if spec.node is not None and spec.node.fully_qualified_name:
        kind = "lifecycle node" if spec.node.lifecycle else "node"
        auto = " (autostart)" if spec.node.autostart else ""
        lines.append(f"  {kind}:    {spec.node.fully_qualified_name}{auto}")
    if spec.machine is not None:
        lines.append(f"  machine: {spec.machine.describe()}")
    lines.append(f"  cwd:     {spec.cwd or '(inherited)'}")
    if spec.env_changes:
        changes = [
            f"{k}={shorten(v, 60)}" if v is not None else f"-{k}"
            for k, v in sorted(spec.env_changes.items())
        ]
        lines.append(f"  env:     {' '.join(changes)}")
    lines.append(f"  output:  {spec.output}")
    lines.append(f"  respawn: {spec.respawn.describe()}")
    stop = (
        f"SIGINT, SIGTERM after {spec.sigterm_timeout:g} s,"
        f" SIGKILL after {spec.sigkill_timeout:g} s more"
    )
    lines.append(f"  stop:    {stop}")
    if spec.required:
        lines.append("  exit:    required: its exit shuts the launch down")
    elif spec.on_exit is not None:
        lines.append(f"  on exit: {spec.on_exit.describe()}")
    params = _params_files(spec, made)
    if made:
        lines.append(
            f"  files:   {', '.join(made.values())}: files mlaunch writes for the run and removes"
            " when it ends" + ("; their parameters are below" if params else "")
        )
    lines.extend(params)
    return lines


def _made_files(argv: Sequence[str], temp_dir: str | None) -> dict[str, str]:
    """The argv items that are files of the run's temporary folder, each with the name --print
    gives it (``<params-file 1>``): the paths --print saw are gone once it exits."""
    if not temp_dir:
        return {}
    made: dict[str, str] = {}
    for previous, arg in zip(("", *argv), argv, strict=False):
        if arg.startswith(temp_dir + os.sep) and arg not in made:
            kind = "params-file" if previous == "--params-file" else "run-file"
            made[arg] = f"<{kind} {len(made) + 1}>"
    return made


def _params_files(spec: ProcessSpec, made: dict[str, str]) -> list[str]:
    """The parameters in the params files mlaunch wrote for this process, one per line."""
    out = []
    for i, arg in enumerate(spec.argv[:-1]):
        if arg != "--params-file":
            continue
        path = spec.argv[i + 1]
        if path not in made:
            continue
        try:
            from mlaunch.plan.yamldata import load as load_yaml

            with open(path, encoding="utf-8") as f:
                data = load_yaml(f.read(), path)
        except (OSError, ValueError):
            continue
        for node, section in (data or {}).items():
            params = (section or {}).get("ros__parameters", {})
            for name, value in _flatten(params):
                out.append(
                    f"  param:   {name} = {value_text(value)}   [{node}]   ({made[path][1:-1]})"
                )
    return out


def _flatten(params: dict[str, object], prefix: str = "") -> list[tuple[str, object]]:
    items: list[tuple[str, object]] = []
    for key, value in params.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict):
            items.extend(_flatten(value, name + "."))
        else:
            items.append((name, value))
    return items


def format_arguments(infos: Sequence[ArgumentInfo]) -> str:
    """The --show-args table: name, default, description (and choices), conditional marked.

    A default with substitutions shows the value they give where it can be worked out before
    running (a package's path), else their description; one longer than its column goes whole
    on a line of its own below the row (never cut or wrapped: it is often a path to copy). An
    argument an including file passes is not required.
    """
    if not infos:
        return "No arguments.\n"
    import textwrap

    rows = []
    any_conditional = False
    for info in infos:
        name = info.name + ("*" if info.conditional else "")
        any_conditional |= info.conditional
        rows.append((name, _default_text(info), info.description))
    w_name = max(len("name"), *(len(r[0]) for r in rows))
    w_def = max([len("default"), *(len(r[1]) for r in rows if len(r[1]) <= 36)])
    width = max(40, _terminal_width() - w_name - w_def - 6)
    out = ["Arguments (pass arguments as '<name>:=<value>'):", ""]
    out.append(f"  {'name':<{w_name}}  {'default':<{w_def}}  description")
    out.append(f"  {'-' * w_name}  {'-' * w_def}  {'-' * min(width, 40)}")
    for name, default, description in rows:
        lines = textwrap.wrap(description, width) or [""]
        long = len(default) > w_def
        for i, text in enumerate(lines):
            shown = "(below)" if long and i == 0 else (default if i == 0 else "")
            out.append(f"  {name if i == 0 else '':<{w_name}}  {shown:<{w_def}}  {text}".rstrip())
        if long:
            out.append(f"  {'':<{w_name}}  default: {default}")
    if any_conditional:
        out += ["", "* argument(s) which are only used if specific conditions occur"]
    return "\n".join(out) + "\n"


def _default_text(info: ArgumentInfo) -> str:
    if info.default is not None:
        return repr(info.resolved if info.resolved is not None else info.default)
    if info.passed_by:
        where = info.passed_by
        file, sep, line = where.rpartition(":")
        return f"(passed by {os.path.basename(file)}:{line})" if sep else f"(passed by {where})"
    return "(required)"


def _terminal_width() -> int:
    try:
        return os.get_terminal_size(1).columns or 100  # 0 from some pseudo-terminals
    except OSError:
        return 100
