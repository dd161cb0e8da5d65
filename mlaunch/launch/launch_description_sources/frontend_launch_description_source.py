"""``launch.launch_description_sources.frontend_launch_description_source``: a markup launch
file (XML, YAML, or a package's format), read by ``launch.frontend``; ``XMLLaunchDescriptionSource``
and ``YAMLLaunchDescriptionSource`` (launch_xml's and launch_yaml's) name the format.
"""

from __future__ import annotations

from mlaunch.launch.launch_description_sources.any_launch_description_source import (
    AnyLaunchDescriptionSource,
)

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    pass


class FrontendLaunchDescriptionSource(AnyLaunchDescriptionSource):
    method_text = "interpreted frontend launch file"


class XMLLaunchDescriptionSource(AnyLaunchDescriptionSource):
    format_hint = "xml"
    method_text = "interpreted XML launch file"


class YAMLLaunchDescriptionSource(AnyLaunchDescriptionSource):
    format_hint = "yaml"
    method_text = "interpreted YAML launch file"
