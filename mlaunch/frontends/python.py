"""The Python frontend: exec a ``*.launch.py`` file and call its generate_launch_description()."""

from __future__ import annotations

import os
import sys
import types

from mlaunch.plan.errors import LaunchFileError, MlaunchError
from mlaunch.plan.origin import unset_variable_hint, user_location

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.launch_description import LaunchDescription


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


def load(path: str) -> LaunchDescription:
    """The description a Python launch file's generate_launch_description() returns.

    The application serves the ROS 2 module names (``mlaunch.compat.install()``) before it loads
    anything, so the file's ``from launch... import`` get mlaunch's classes.
    """
    from mlaunch.launch.launch_description import LaunchDescription

    try:
        with open(path, "rb") as f:
            source = f.read()
    except OSError as e:
        raise LaunchFileError(f"cannot read launch file: {e.strerror}", where=path)
    try:
        # Compiled from bytes, as Python imports it: a ``# coding:`` line is honoured.
        code = compile(source, path, "exec")
    except SyntaxError as e:
        if "codec can't decode" in str(e.msg):
            from mlaunch.frontends.encoding import not_utf8  # error path only

            raise not_utf8(source, path) or LaunchFileError(e.msg, where=f"{path}:{e.lineno}")
        col = f":{e.offset}" if e.offset else ""
        raise LaunchFileError(f"Python syntax error: {e.msg}", where=f"{path}:{e.lineno}{col}")
    check_encoding(source, path)
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


def check_encoding(source: bytes, path: str) -> None:
    """Refuse bytes that are not UTF-8 without a ``# coding:`` line, wherever they are.

    compile() of bytes lets a bad byte in a comment through; Python's import and ros2 launch
    refuse the file ("Non-UTF-8 code starting with '\\xe9'"), and so does mlaunch.
    """
    try:
        source.decode("utf-8")
    except UnicodeDecodeError:
        import re  # error path only

        head = source.split(b"\n", 2)[:2]
        if any(re.match(rb"[ \t\f]*#.*?coding[:=][ \t]*[-\w.]+", line) for line in head):
            return
        from mlaunch.frontends.encoding import not_utf8

        raise not_utf8(source, path) or LaunchFileError("the file is not UTF-8", where=path)


def run_user_code(path: str, call: Any, during: str) -> Any:
    """Run launch-file code; any exception becomes one located error line."""
    try:
        return call()
    except SystemExit as e:  # the launch file's sys.exit() must not end mlaunch silently
        raise exit_error(e, path, during) from e
    except MlaunchError as e:
        if e.where is None:
            e.where = user_location(e.__traceback__, os.path.abspath(path)) or path
        raise
    except Exception as e:
        where = user_location(e.__traceback__, os.path.abspath(path)) or path
        hint = unset_variable_hint(e)
        raise LaunchFileError(f"{type(e).__name__} {during}: {e}{hint}", where=where) from e


def exit_error(e: SystemExit, path: str, during: str) -> LaunchFileError:
    """The located error for a launch file that called ``sys.exit()`` (or raised SystemExit)."""
    where = user_location(e.__traceback__, os.path.abspath(path)) or path
    return LaunchFileError(
        f"the launch file called sys.exit({e.code!r}) {during}; a launch file cannot end"
        " mlaunch: raise an exception to report an error, or use a Shutdown action",
        where=where,
    )
