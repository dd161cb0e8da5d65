"""ROS-facing helpers: the ament index, node command lines, params files, and the rclpy bridge.

``package_settings`` holds what the command line says about finding packages until
``mlaunch.ros.packages`` is first imported (a launch file without ROS parts never imports it).
"""

from __future__ import annotations

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Mapping, Sequence
    from typing import Any

package_settings: dict[str, Any] | None = None


def configure_packages(
    search_paths: Sequence[str], launch_file: str | None, environ: Mapping[str, str]
) -> None:
    """Record the package search settings; applied now if the lookup is already loaded."""
    global package_settings
    package_settings = {
        "search_paths": tuple(search_paths),
        "launch_file": launch_file,
        "environ": environ,
    }
    import sys

    packages = sys.modules.get("mlaunch.ros.packages")
    if packages is not None:
        packages.configure(**package_settings)
