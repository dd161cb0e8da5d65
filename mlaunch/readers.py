"""Read a launch file of any format into a LaunchDescription: the reader is chosen by the file's
suffix, never by trying. ROS 2's Python, YAML and XML (mlaunch.frontends) and ROS 1's roslaunch
XML (mlaunch.ros1) sit below this module, in the same layer."""

from __future__ import annotations

import importlib
import os

from mlaunch.frontends.limits import allow_deep_trees
from mlaunch.plan.errors import LaunchFileError, is_own_module

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.launch_description import LaunchDescription

# suffix -> module with load(path) -> LaunchDescription. Longest suffix wins.
FRONTENDS: dict[str, str] = {
    ".launch.py": "mlaunch.frontends.python",
    ".py": "mlaunch.frontends.python",
    ".launch.yaml": "mlaunch.frontends.yaml",
    ".launch.yml": "mlaunch.frontends.yaml",
    ".yaml": "mlaunch.frontends.yaml",
    ".yml": "mlaunch.frontends.yaml",
    ".launch.xml": "mlaunch.frontends.xml",
    ".xml": "mlaunch.frontends.xml",
    ".launch": "mlaunch.ros1.roslaunch",
}

FORMAT_MODULES = {
    "python": "mlaunch.frontends.python",
    "yaml": "mlaunch.frontends.yaml",
    "xml": "mlaunch.frontends.xml",
}
# A file a roslaunch file includes: roslaunch XML whatever its suffix (ROS 1 packages name their
# fragments *.launch.xml).
ROSLAUNCH_HINT = "roslaunch"


def frontend_for(path: str, hint: str | None = None) -> str:
    if hint == ROSLAUNCH_HINT:
        return FRONTENDS[".launch"]
    name = os.path.basename(path).lower()
    for suffix in sorted(FRONTENDS, key=len, reverse=True):
        if name.endswith(suffix):
            return FRONTENDS[suffix]
    if hint in FORMAT_MODULES:
        return FORMAT_MODULES[hint]
    valid = ", ".join(
        sorted({s for s in FRONTENDS if s.count(".") == 2} | {".py", ".xml", ".yaml", ".launch"})
    )
    raise LaunchFileError(
        f"cannot tell the launch file format of {path!r} from its name; valid suffixes: {valid}"
    )


def load_root(path: str) -> Any:
    """The root Entity of a YAML or XML launch file, read but not built (for --check)."""
    module_name = frontend_for(path)
    if module_name not in ("mlaunch.frontends.yaml", "mlaunch.frontends.xml"):
        raise LaunchFileError(f"{path!r} is not a YAML or XML launch file")
    return importlib.import_module(module_name).read_root(path)


def load(path: str, hint: str | None = None) -> LaunchDescription:
    """The LaunchDescription in the file at ``path`` (absolute), with every error located."""
    if not os.path.exists(path):
        raise LaunchFileError(f"launch file {path!r} does not exist")
    if os.path.isdir(path):
        raise LaunchFileError(f"{path!r} is a directory, not a launch file")
    module_name = frontend_for(path, hint)
    allow_deep_trees()
    try:
        module = importlib.import_module(module_name)
    except ModuleNotFoundError as e:
        if is_own_module(e.name):
            raise  # a part of mlaunch is missing: a broken installation, reported as a bug
        raise LaunchFileError(
            f"reading {path!r} needs the Python package {e.name!r}, which is not installed"
            " (reinstall mlaunch with its dependencies: pip install mlaunch)"
        ) from e
    # Every frontend module's load() returns a LaunchDescription; import_module cannot say so.
    description: LaunchDescription = module.load(path)
    return description
