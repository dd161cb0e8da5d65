"""Finding the processes a test means (by action or by name), and KeepAliveProc."""

from __future__ import annotations

import sys

from mlaunch.launch.actions import ExecuteProcess

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

# ``cmd_args=NO_CMD_ARGS`` matches a process started without arguments.
NO_CMD_ARGS = object()

_KEEP_ALIVE_SCRIPT = """
import signal, time
signal.signal(signal.SIGINT, lambda *_: exit(0))
signal.signal(signal.SIGTERM, lambda *_: exit(0))
while True:
    time.sleep(3600)
"""


class NoMatchingProcessException(Exception):
    """No recorded process matches what the test asked for (yet)."""


def KeepAliveProc() -> ExecuteProcess:
    """A process that does nothing until it is stopped, so the launch outlives the ones tested.

    It exits 0 when stopped, so ``assertExitCodes`` over every process still passes.
    """
    return ExecuteProcess(cmd=[sys.executable, "-c", _KEEP_ALIVE_SCRIPT], name="keep_alive")


def describe_process(action: Any) -> str:
    """``name args...`` of a process for messages: its real argv once started."""
    details = getattr(action, "process_details", None)
    if details:
        return " ".join([details["name"], *details["cmd"][1:]])
    texts = []
    for item in getattr(action, "cmd", []):
        parts = item if isinstance(item, list) else [item]
        if not all(type(p).__name__ == "TextSubstitution" for p in parts):
            return "(not started yet)"
        texts.append("".join(p.text for p in parts))
    return " ".join(texts) or type(action).__name__


def _matches_name(action: Any, name: str, cmd_args: Any) -> bool:
    details = getattr(action, "process_details", None)
    if not details or name not in details["name"]:
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
    """The actions in ``info_obj`` (a ProcInfoHandler or IoHandler) that ``process`` names.

    ``process``: None (all of them), an ExecuteProcess action, or a string found in the process
    name (with ``cmd_args`` narrowing it down). More than one match for a string is an error
    when ``strict_proc_matching``.
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
        raise TypeError(
            f"process must be an ExecuteProcess action or a str, not {type(process).__name__}"
        )
    if isinstance(cmd_args, str):
        cmd_args = [cmd_args]
    matches = [action for action in known if _matches_name(action, process, cmd_args)]
    names = ", ".join(sorted(describe_process(p) for p in known))
    if not matches:
        raise NoMatchingProcessException(
            f"Did not find any processes matching name {process!r} and args {cmd_args!r}."
            f" Procs: {names}"
        )
    if strict_proc_matching and len(matches) > 1:
        raise Exception(
            f"Found multiple processes matching name {process!r} and cmd_args {cmd_args!r}."
            f" Procs: {names}"
        )
    return matches


__all__ = ["NO_CMD_ARGS", "KeepAliveProc", "NoMatchingProcessException", "resolveProcesses"]
