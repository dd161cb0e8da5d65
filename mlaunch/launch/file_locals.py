"""The file locals an include sets (ThisLaunchFile, ThisLaunchFileDir, ``$(dirname)`` ...).

Jazzy's include points ``current_launch_file_path``/``current_launch_file_directory`` at the
included file before its arguments are performed, and leaves them there: an argument, and every
action of the includer after the include, sees the included file's (ros2/launch#618, fixed after
Jazzy by PR #862, which scopes them to the include). mlaunch does as Jazzy by default, and keeps
beside the locals the includer's own (PR #862's) under ``OWN_KEY``: where a substitution gets a
value that differs, it warns once at the action's file:line. ``--scoped-file-locals`` (or a
comment ``mlaunch: scoped-file-locals`` in the includer) gives PR #862's behaviour; ROS 1 files
keep roslaunch's (their includes carry ``keep_file_locals``).
"""

from __future__ import annotations

import os

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext

PATH = "current_launch_file_path"
DIRECTORY = "current_launch_file_directory"
# The file locals under PR #862's rule, where they differ from launch's (absent: the same).
OWN_KEY = "mlaunch_own_file_locals"
# The context globals' set of (origin, substitution) already warned about.
_WARNED_KEY = "mlaunch_file_locals_warned"


def of_location(location: str) -> dict[str, str]:
    """The locals of an included file at ``location`` (a name such as ``<script>`` when it is
    no file: its folder is the name itself, as launch's)."""
    absolute = os.path.abspath(location)
    directory = os.path.dirname(absolute) if os.path.exists(absolute) else location
    return {PATH: absolute, DIRECTORY: directory}


def own(values: dict[str, Any]) -> dict[str, Any]:
    """The file locals PR #862's rule gives where the locals are ``values``."""
    kept = values.get(OWN_KEY)
    return (
        dict(kept)
        if kept is not None
        else {PATH: values.get(PATH), DIRECTORY: values.get(DIRECTORY)}
    )


def point_at(context: Any, file_locals: dict[str, str]) -> None:
    """Jazzy's include: the locals are the included file's from now on, the includer's own
    noted (its arguments are performed next, and the actions after it see the file's too)."""
    values: dict[str, Any] = context._locals
    includer = own(values)
    values.update(file_locals)
    _note_own(values, includer)


def _note_own(values: dict[str, Any], own_values: dict[str, Any]) -> None:
    if own_values.get(PATH) == values.get(PATH) and own_values.get(DIRECTORY) == values.get(
        DIRECTORY
    ):
        values.pop(OWN_KEY, None)
    else:
        values[OWN_KEY] = own_values


def is_scoped(context: Any, action: Any) -> bool:
    """Whether ``action`` (an include) keeps its file locals to itself: the option, the
    includer's comment, or ``keep_file_locals`` (ROS 1 files' includes)."""
    if getattr(action, "keep_file_locals", False):
        return True
    planner = getattr(context, "_planner", None)
    if planner is not None and planner.options.scoped_file_locals:
        return True
    from mlaunch.plan.pragmas import SCOPED_FILE_LOCALS, file_has

    return file_has(action.origin or "", SCOPED_FILE_LOCALS)


def enter(context: Any, file_locals: dict[str, str]) -> None:
    """Inside an included file: its locals, its own under either rule."""
    values: dict[str, Any] = context._locals
    values.update(file_locals)
    values.pop(OWN_KEY, None)


def leave(context: Any, before: dict[str, Any], scoped: bool) -> None:
    """After an included file: the includer's locals ``before`` the include back (``scoped``),
    or launch's left as the file set them, with the includer's own noted where they differ."""
    if scoped:
        context._locals = before
    else:
        _note_own(context._locals, own(before))


def checked(context: LaunchContext, key: str, value: str, what: str) -> str:
    """``value`` of the local ``key``, with a warning (once per place) when PR #862's rule would
    give another: the file located by the action being visited."""
    kept = context._locals.get(OWN_KEY)
    if kept is None or kept.get(key) is None or kept[key] == value:
        return value
    planner = context._planner
    origin = getattr(planner, "visiting", "") if planner is not None else ""
    warned: set[tuple[str, str]] | None = context._globals.get(_WARNED_KEY)
    if warned is None:
        warned = set()
        context._globals[_WARNED_KEY] = warned
    if (origin, what) in warned:
        return value
    warned.add((origin, what))
    context.warn(
        f"{origin or 'a launch file'}: {what} gives {value}, the included file's, as ros2"
        f" launch (Jazzy) gives after an include (ros2/launch#618); --scoped-file-locals, or a"
        f" comment 'mlaunch: scoped-file-locals' in the file, gives the includer's {kept[key]}"
    )
    return value
