"""Finding the processes a test means: by action, or by a name (and arguments) they started with.

``resolveProcesses(info_obj, process=..., cmd_args=...)`` is what every assertion and wait of
launch_testing goes through; ``info_obj`` is a ProcInfoHandler or an IoHandler.
"""

from __future__ import annotations

from mlaunch.launch.actions.execute_process import ExecuteProcess

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

# ``cmd_args=NO_CMD_ARGS`` matches a process started without arguments.
NO_CMD_ARGS = object()

# What a process that has not started is called when its command needs the launch to resolve.
NOT_LAUNCHED = "Unknown - Process not launched yet"


class NoMatchingProcessException(Exception):
    """No recorded process matches what the test asked for (yet)."""


class _NeedsLaunch(Exception):
    """A substitution asked the (absent) launch context for something."""


class _NoContext:
    """Stands in for a launch context: text substitutions never touch it, others do."""

    def __getattr__(self, name: str) -> Any:
        raise _NeedsLaunch(name)


def _command_of(action: Any) -> list[Any]:
    """The unresolved command of an ExecuteProcess (or of an ExecuteLocal's description)."""
    description = getattr(action, "process_description", None)
    cmd = getattr(action, "cmd", None)
    if cmd is None and description is not None:
        cmd = getattr(description, "cmd", None)
    return list(cmd or [])


def describe_process(action: Any) -> str:
    """``name args...`` of a process for messages: its real argv once started, else its command
    when that is plain text, else NOT_LAUNCHED."""
    details = getattr(action, "process_details", None)
    if details:
        return f"{details['name']} {' '.join(details['cmd'][1:])}"
    try:
        return " ".join(_text_of(item) for item in _command_of(action))
    except Exception:
        # _NeedsLaunch, or the failure a substitution wraps it in: only the launch can say.
        return NOT_LAUNCHED


def _text_of(item: Any) -> str:
    """One command word performed without a launch: text parts only (else _NeedsLaunch)."""
    parts = item if isinstance(item, (list, tuple)) else [item]
    context = _NoContext()
    return "".join(part if isinstance(part, str) else part.perform(context) for part in parts)


def _matches_name(action: Any, name: str, cmd_args: Any) -> bool:
    details = action.process_details
    if name not in details["name"]:
        return False
    args = details["cmd"][1:]
    if cmd_args is None:
        return True
    if cmd_args is NO_CMD_ARGS:
        return not args
    return all(arg in args for arg in cmd_args)


def resolveProcesses(
    info_obj: Any,
    *,
    process: Any = None,
    cmd_args: Any = None,
    strict_proc_matching: bool = True,
) -> list[Any]:
    """The actions in ``info_obj`` that ``process`` names.

    ``process``: None (all of them), an ExecuteProcess action, or a string found in the process
    name (``cmd_args`` narrows it down: a list of arguments it must have, one string, or
    NO_CMD_ARGS). More than one match for a string is an error when ``strict_proc_matching``.
    """
    known = list(info_obj.processes())
    if process is None:
        if not known:
            raise NoMatchingProcessException("No data recorded for any process")
        return known
    if isinstance(process, ExecuteProcess):
        if process in known:
            return [process]
        raise NoMatchingProcessException(f"No data recorded for proc {describe_process(process)}")
    if not isinstance(process, str):
        raise TypeError(f"proc argument must be 'ExecuteProcess' or 'str' not {type(process)}")
    if isinstance(cmd_args, str):
        cmd_args = [cmd_args]  # the old spelling: one argument as a string
    matches = [action for action in known if _matches_name(action, process, cmd_args)]
    if matches and not (strict_proc_matching and len(matches) > 1):
        return matches
    names = ", ".join(sorted(describe_process(p) for p in known))
    if not matches:
        raise NoMatchingProcessException(
            f"Did not find any processes matching name '{process}' and args '{cmd_args}'."
            f" Procs: {names}"
        )
    raise Exception(
        f"Found multiple processes matching name '{process}' and cmd_args '{cmd_args}'."
        f" Procs: {names}"
    )


__all__ = ["NO_CMD_ARGS", "NoMatchingProcessException", "describe_process", "resolveProcesses"]
