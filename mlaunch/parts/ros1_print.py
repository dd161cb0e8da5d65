"""What ``--print`` shows of a native ROS 1 run: the nodes that start once the parameter
server is loaded (they are in a handler of the loader's exit, not in the plan's first steps),
each with its command line, the environment roslaunch gives it, its working folder, stop
ladder, respawn and the parameters it reads, and then the parameter server itself."""

from __future__ import annotations

import shlex
from collections.abc import Mapping
from typing import Any

from mlaunch.launch.action import Action
from mlaunch.parts.ros1_environ import shell_environ
from mlaunch.plan.steps import Note
from mlaunch.plan.text import rel, shorten, value_text
from mlaunch.ros1.config import Ros1Node

# Longest value shown for one parameter (a robot description is thousands of characters).
VALUE_WIDTH = 100


class NativeNode:
    """One node as a native run starts it: its resolution and its process's command line,
    environment (None: another computer's, set there) and working folder."""

    __slots__ = ("argv", "cwd", "env", "node", "sigkill_timeout", "sigterm_timeout")

    def __init__(
        self,
        node: Ros1Node,
        argv: list[str],
        env: dict[str, str] | None,
        cwd: str | None,
        stop: tuple[float, float],
    ) -> None:
        self.node, self.argv, self.env, self.cwd = node, argv, env, cwd
        self.sigterm_timeout, self.sigkill_timeout = stop


class NativeNodes(Note):
    """The nodes a native ROS 1 run starts after loading its parameter server (a Note: the
    supervisor carries nothing out for it; the handler of the loader's exit starts them)."""

    __slots__ = ("environ", "nodes", "params")
    _fields = (*Note._fields, "nodes", "params")

    def __init__(
        self,
        origin: str,
        nodes: list[NativeNode],
        params: Mapping[str, Any],
        environ: Mapping[str, str],
    ) -> None:
        self.origin = origin
        self.nodes = nodes
        self.params = dict(params)
        self.environ = shell_environ(environ)

    def describe_lines(self) -> list[str]:
        out = [f"once the parameter server is loaded, {len(self.nodes)} node(s) start:", ""]
        for native in self.nodes:
            out += [*self._node_lines(native), ""]
        out.append(f"parameter server: {len(self.params)} parameter(s), loaded first:")
        out += [f"  {name} = {_value(value)}" for name, value in sorted(self.params.items())]
        return out

    def _node_lines(self, native: NativeNode) -> list[str]:
        node = native.node
        lines = [f"{node.name}   {rel(node.origin)}" if node.origin else node.name]
        lines.append(f"  argv:    {shorten(shlex.join(native.argv), 400)}")
        lines.append(f"  node:    {node.full_name}")
        if node.machine:
            lines.append(f"  machine: {node.machine}")
        lines.append(f"  cwd:     {native.cwd or '(its login folder there)'}")
        changes = env_changes(self.environ, native.env)
        if changes:
            lines.append(f"  env:     {' '.join(changes)}")
        lines.append(f"  output:  {'screen' if node.output == 'screen' else 'log'}")
        respawn = f"yes, after {node.respawn_delay:g} s" if node.respawn else "no"
        lines.append(f"  respawn: {respawn if node.respawn_delay else respawn.split(',')[0]}")
        lines.append(
            f"  stop:    SIGINT, SIGTERM after {native.sigterm_timeout:g} s,"
            f" SIGKILL after {native.sigkill_timeout:g} s more"
        )
        if node.required:
            lines.append("  exit:    required: its exit shuts the launch down")
        own = {k: v for k, v in self.params.items() if k.startswith(node.full_name + "/")}
        for name, value in sorted(own.items()):
            lines.append(f"  param:   {name} = {_value(value)}")
        return lines

    def describe_data(self) -> dict[str, Any]:
        """--print --format json: the same, as data."""
        nodes = []
        for native in self.nodes:
            node = native.node
            nodes.append(
                {
                    "name": node.full_name,
                    "origin": node.origin,
                    "argv": native.argv,
                    "cwd": native.cwd,
                    "env": None if native.env is None else _changed(self.environ, native.env),
                    "output": "screen" if node.output == "screen" else "log",
                    "respawn": node.respawn,
                    "respawn_delay": node.respawn_delay,
                    "required": node.required,
                    "sigterm_timeout": native.sigterm_timeout,
                    "sigkill_timeout": native.sigkill_timeout,
                    "machine": node.machine,
                }
            )
        params = {k: value_text(v) for k, v in sorted(self.params.items())}
        return {"kind": "ros1_nodes", "nodes": nodes, "params": params}


def _changed(before: Mapping[str, str], after: Mapping[str, str]) -> dict[str, str | None]:
    out: dict[str, str | None] = {k: v for k, v in after.items() if before.get(k) != v}
    out.update({k: None for k in before if k not in after})
    return dict(sorted(out.items()))


def env_changes(before: Mapping[str, str], after: Mapping[str, str] | None) -> list[str]:
    """``NAME=value`` for what the node's environment sets or changes, ``-NAME`` for what it
    takes out, against the environment mlaunch was started with."""
    if after is None:
        return ["(its login environment there, plus ROS_MASTER_URI, ROS_NAMESPACE, <env>)"]
    return [
        f"{k}={shorten(v, 60)}" if v is not None else f"-{k}"
        for k, v in _changed(before, after).items()
    ]


def _value(value: Any) -> str:
    return f"{shorten(value_text(value), VALUE_WIDTH)} ({type(value).__name__})"


class DescribeNodes(Action):
    """Adds the NativeNodes note to the plan, where the loader starts (for --print)."""

    def __init__(self, note: NativeNodes) -> None:
        super().__init__()
        self.note = note

    def execute(self, context: Any) -> None:
        context.planner.add(self.note)
