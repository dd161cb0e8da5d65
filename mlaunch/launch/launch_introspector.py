"""``LaunchIntrospector``: a launch description as an indented tree of text, as launch prints it.

Each action gives one line (LogInfo, EmitEvent, ExecuteProcess and RegisterEventHandler in
launch's words, any other as ``Action('...')``); an event handler's entities are indented under
its registration.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from mlaunch.launch.substitution import normalize

INDENT = "    "


def indent(lines: list[str], indention: str = INDENT) -> list[str]:
    """``lines``, each prefixed with ``indention``."""
    return [indention + line for line in lines]


def format_substitutions(substitutions: Any) -> str:
    """Substitutions described and joined with ' + '."""
    return " + ".join(sub.describe() for sub in normalize(substitutions))


def format_entities(entities: Iterable[Any]) -> list[str]:
    """The lines of each entity in turn."""
    from mlaunch.launch.action import Action

    lines: list[str] = []
    for entity in entities:
        if isinstance(entity, Action):
            lines.extend(format_action(entity))
        else:
            lines.append(f"Unknown entity('{entity}')")
    return lines


def format_event_handler(event_handler: Any) -> list[str]:
    """The handler's description, its entities indented under it."""
    describe = getattr(event_handler, "describe", None)
    if describe is None:
        return [f"EventHandler('{hex(id(event_handler))}')"]
    text, entities = describe()
    return [text, *indent(format_entities(entities))]


def _process_line(action: Any) -> str:
    cmd = ", ".join(format_substitutions(part) for part in action.cmd)
    cwd = action.cwd
    cwd_text = "None" if cwd is None else f"'{format_substitutions(cwd)}'"
    env = action.env
    if env is None:
        env_text = "None"
    else:
        pairs = env.items() if isinstance(env, dict) else env
        env_text = (
            "{"
            + ", ".join(f"{format_substitutions(k)}: {format_substitutions(v)}" for k, v in pairs)
            + "}"
        )
    return f"ExecuteProcess(cmd=[{cmd}], cwd={cwd_text}, env={env_text}, shell={action.shell})"


def format_action(action: Any) -> list[str]:
    """One action's lines."""
    from mlaunch.launch.actions.emit_event import EmitEvent
    from mlaunch.launch.actions.execute_process import ExecuteProcess
    from mlaunch.launch.actions.log_info import LogInfo
    from mlaunch.launch.actions.register_event_handler import RegisterEventHandler

    if isinstance(action, LogInfo):
        return [f"LogInfo({' + '.join(s.describe() for s in action.msg)})"]
    if isinstance(action, EmitEvent):
        return [f"EmitEvent(event='{action.event.name}')"]
    if isinstance(action, ExecuteProcess):
        return [_process_line(action)]
    if isinstance(action, RegisterEventHandler):
        handler = action.event_handler
        return [f"RegisterEventHandler('{handler}'):", *indent(format_event_handler(handler))]
    return [f"Action('{action}')"]


def tree_like_indent(lines: list[str]) -> list[str]:
    """Indented lines drawn as a tree: '└── ' before each entry, '│' down to its siblings."""
    result: list[str] = []
    depths: list[int] = []
    for line in lines:
        if not line.startswith(INDENT):
            continue
        depth = len(line) - len(line.lstrip())
        result.append(line[: depth - 4] + "└── " + line[depth:])
        depths.append(depth)
    for i, depth in enumerate(depths):
        # A later sibling at this depth (before a shallower line) turns the corner into a tee
        # and draws the bar through the lines in between.
        for j in range(i + 1, len(depths)):
            if depths[j] < depth:
                break
            if depths[j] == depth:
                result[i] = result[i][: depth - 4] + "├" + result[i][depth - 3 :]
                for k in range(i + 1, j):
                    row = result[k]
                    result[k] = row[: depth - 4] + "│" + row[depth - 3 :]
                break
    return result


class LaunchIntrospector:
    """Text views of launch descriptions, for scripts that print what a file would do."""

    def format_launch_description(self, launch_description: Any) -> str:
        """The description's repr, then its entities as a tree."""
        lines = tree_like_indent(indent(format_entities(launch_description.entities)))
        return f"{launch_description}\n" + "\n".join(lines)


__all__ = [
    "LaunchIntrospector",
    "format_action",
    "format_entities",
    "format_event_handler",
    "format_substitutions",
    "indent",
    "tree_like_indent",
]
