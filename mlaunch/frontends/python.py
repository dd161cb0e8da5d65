"""The Python frontend: exec a ``*.launch.py`` file and call its generate_launch_description()."""

from __future__ import annotations

import os
import sys
import types

from mlaunch.errors import LaunchFileError, MlaunchError
from mlaunch.origin import user_location

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any


def set_launch_argv(target: str, second: str | None, arguments: list[str]) -> None:
    """Lay sys.argv out as ``ros2 launch`` does, for launch files that read it.

    Some well-known packages parse ``sys.argv`` inside generate_launch_description(), assuming
    ``ros2 launch [PKG] FILE name:=value ...``: the arguments from index 3 (FILE) or 4 (PKG FILE).
    The program name stays mlaunch's own; the launch file sees this for the whole run, as under
    ros2 launch, where it is simply the process's command line.
    """
    sys.argv = [sys.argv[0] if sys.argv else "mlaunch", "launch", target]
    if second is not None:
        sys.argv.append(second)
    sys.argv.extend(arguments)


def load(path: str) -> Any:
    from mlaunch import compat
    from mlaunch.launch.actions import LaunchDescription

    compat.install()
    try:
        with open(path, encoding="utf-8") as f:
            source = f.read()
    except (OSError, UnicodeDecodeError) as e:
        raise LaunchFileError(f"cannot read launch file: {e}", where=path)
    try:
        code = compile(source, path, "exec")
    except SyntaxError as e:
        col = f":{e.offset}" if e.offset else ""
        raise LaunchFileError(f"Python syntax error: {e.msg}", where=f"{path}:{e.lineno}{col}")
    module = types.ModuleType("python_launch_file")
    module.__file__ = path
    run_user_code(path, lambda: exec(code, module.__dict__), "while loading the launch file")
    generate = getattr(module, "generate_launch_description", None)
    if not callable(generate):
        raise LaunchFileError("defines no generate_launch_description() function", where=path)
    description = run_user_code(path, generate, "in generate_launch_description()")
    if not isinstance(description, LaunchDescription):
        raise LaunchFileError(
            "generate_launch_description() returned"
            f" {type(description).__name__}, expected a LaunchDescription",
            where=path,
        )
    return description


def run_user_code(path: str, call: Any, during: str) -> Any:
    """Run launch-file code; any exception becomes one located error line."""
    try:
        return call()
    except MlaunchError as e:
        if e.where is None:
            e.where = user_location(e.__traceback__, os.path.abspath(path)) or path
        raise
    except Exception as e:
        where = user_location(e.__traceback__, os.path.abspath(path)) or path
        raise LaunchFileError(f"{type(e).__name__} {during}: {e}", where=where) from e
