"""The opt-in comments a launch file may carry, read once per file.

``# mlaunch: capture-at-definition`` (timers and handlers take the values where they are written,
mlaunch.resolve.binding) and ``# mlaunch: scoped-parameters`` (SetParameter and SetRemap stay in
their group, mlaunch.launch_ros.scope) and ``# mlaunch: scoped-file-locals`` (an include's
arguments and the actions after it keep the includer's ThisLaunchFileDir, mlaunch.launch.
file_locals): comments, so the file runs unchanged under ros2 launch.
"""

from __future__ import annotations

import re

PRAGMA = "mlaunch: capture-at-definition"
SCOPED_PARAMETERS = "mlaunch: scoped-parameters"
SCOPED_FILE_LOCALS = "mlaunch: scoped-file-locals"

_FILES: dict[str, str] = {}
_PRAGMAS: dict[tuple[str, str], bool] = {}


def file_captures(origin: str) -> bool:
    """Whether the launch file of ``origin`` (``path:line``) asks for capture-at-definition."""
    return file_has(origin, PRAGMA)


def file_has(origin: str, pragma: str) -> bool:
    """Whether the launch file of ``origin`` (``path:line``) has ``pragma`` as a comment line:
    ``# ...`` (Python, YAML) or ``<!-- ... -->`` (XML), so the file runs unchanged in ros2."""
    if not origin:
        return False
    path = origin.rsplit(":", 1)[0] if origin[-1:].isdigit() else origin
    if path not in _FILES:
        try:
            with open(path, encoding="utf-8", errors="replace") as f:
                _FILES[path] = f.read()
        except OSError:
            _FILES[path] = ""
    key = (path, pragma)
    if key not in _PRAGMAS:
        line = re.compile(r"^[ \t]*(#|<!--)[ \t]*" + re.escape(pragma), re.MULTILINE)
        _PRAGMAS[key] = line.search(_FILES[path]) is not None
    return _PRAGMAS[key]
