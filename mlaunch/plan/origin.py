"""Where an action was written: ``file:line`` of the user's code that built it."""

from __future__ import annotations

import os
import sys
from types import TracebackType

# mlaunch/plan/origin.py -> mlaunch/: every frame of mlaunch's own code
_PACKAGE_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__))) + os.sep
# The stand-ins' shares hold launch files (mlaunch.standins.SHARE): their lines are a user's.
_SHARE_DIR = os.path.join(_PACKAGE_DIR, "standins", "share") + os.sep


def is_mlaunch_file(filename: str) -> bool:
    return filename.startswith(_PACKAGE_DIR) and not filename.startswith(_SHARE_DIR)


def caller_origin() -> str:
    """``file:line`` of the first frame outside mlaunch (the launch file line building an action).

    Frontends that build actions from YAML/XML overwrite ``origin`` with the tag's own line.
    """
    frame = sys._getframe(1)
    while frame is not None:
        filename = frame.f_code.co_filename
        if not is_mlaunch_file(filename) and not filename.startswith("<frozen"):
            return f"{filename}:{frame.f_lineno}"
        frame = frame.f_back  # type: ignore[assignment]
    return ""


def user_location(tb: TracebackType | None, prefer: str | None = None) -> str | None:
    """The innermost traceback frame in ``prefer`` (the launch file), else outside mlaunch."""
    best_preferred = None
    best_other = None
    while tb is not None:
        filename = tb.tb_frame.f_code.co_filename
        if prefer is not None and os.path.abspath(filename) == prefer:
            best_preferred = f"{filename}:{tb.tb_lineno}"
        elif not is_mlaunch_file(filename) and not filename.startswith("<"):
            best_other = f"{filename}:{tb.tb_lineno}"
        tb = tb.tb_next
    return best_preferred or best_other


def unset_variable_hint(e: BaseException) -> str:
    """What to do, when ``e`` is the KeyError of ``os.environ[NAME]`` in the user's code: a
    bare ``KeyError: 'TURTLEBOT3_MODEL'`` does not say it is an environment variable."""
    if not isinstance(e, KeyError) or len(e.args) != 1 or not isinstance(e.args[0], str):
        return ""
    tb = e.__traceback__
    while tb is not None and tb.tb_next is not None:
        tb = tb.tb_next
    if tb is None or tb.tb_frame.f_locals.get("self") is not os.environ:
        return ""
    name = e.args[0]
    return (
        f" ({name} is an environment variable the file reads, and it is not set: 'export"
        f" {name}=VALUE' first, or run '{name}=VALUE mlaunch ...')"
    )
