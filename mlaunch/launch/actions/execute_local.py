"""``launch.actions.execute_local``: ``ExecuteLocal``, a process on this machine (mlaunch's
ExecuteProcess with upstream's keywords of the base class).
"""

from __future__ import annotations

from mlaunch.launch.actions.execute_process import ExecuteProcess

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any


class ExecuteLocal(ExecuteProcess):
    """launch's ExecuteLocal: the process given as an ``Executable`` description (its command,
    prefix, name, folder and environment), with ExecuteProcess's other keywords."""

    def __init__(self, *, process_description: Any, **kwargs: Any) -> None:
        given = process_description.given
        super().__init__(
            cmd=given["cmd"],
            prefix=given["prefix"],
            name=given["name"],
            cwd=given["cwd"],
            env=given["env"],
            additional_env=given["additional_env"],
            **kwargs,
        )
        self.process_description = process_description
