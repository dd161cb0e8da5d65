"""``launch.launch_description_sources.python_launch_description_source``: a Python launch file."""

from __future__ import annotations

from mlaunch.launch.launch_description_sources.any_launch_description_source import (
    AnyLaunchDescriptionSource,
)

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    pass


class PythonLaunchDescriptionSource(AnyLaunchDescriptionSource):
    format_hint = "python"
    method_text = "interpreted python launch file"
