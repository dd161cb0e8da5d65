"""``launch.launch_description_sources``: where an included launch description comes from: a path
(any format) or a built description.

Each source lives in its own module, named as upstream's; the base class is
``launch.launch_description_source``. This package only gathers the names
(``mlaunch.launch.gathering``); the Python file loaders load when asked for (they import
importlib's file machinery).
"""

from __future__ import annotations

from mlaunch.launch.gathering import Gathered

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.launch.invalid_launch_file_error import (
        InvalidLaunchFileError,
    )
    from mlaunch.launch.launch_description_source import LaunchDescriptionSource
    from mlaunch.launch.launch_description_sources.any_launch_description_source import (
        AnyLaunchDescriptionSource,
    )
    from mlaunch.launch.launch_description_sources.frontend_launch_description_source import (
        FrontendLaunchDescriptionSource,
        XMLLaunchDescriptionSource,
        YAMLLaunchDescriptionSource,
    )
    from mlaunch.launch.launch_description_sources.python_launch_description_source import (
        PythonLaunchDescriptionSource,
    )
    from mlaunch.launch.launch_description_sources.python_launch_file_utilities import (
        InvalidPythonLaunchFileError,
        get_launch_description_from_python_launch_file,
        load_python_launch_file_as_module,
    )

_gathered = Gathered(
    globals(),
    {
        "AnyLaunchDescriptionSource": ".any_launch_description_source",
        "FrontendLaunchDescriptionSource": ".frontend_launch_description_source",
        "InvalidLaunchFileError": "mlaunch.launch.invalid_launch_file_error",
        "InvalidPythonLaunchFileError": ".python_launch_file_utilities",
        "LaunchDescriptionSource": "mlaunch.launch.launch_description_source",
        "PythonLaunchDescriptionSource": ".python_launch_description_source",
        "XMLLaunchDescriptionSource": ".frontend_launch_description_source",
        "YAMLLaunchDescriptionSource": ".frontend_launch_description_source",
        "get_launch_description_from_python_launch_file": ".python_launch_file_utilities",
        "load_python_launch_file_as_module": ".python_launch_file_utilities",
    },
    submodules=(
        "any_launch_description_source",
        "frontend_launch_description_source",
        "python_launch_description_source",
        "python_launch_file_utilities",
    ),
)
__getattr__ = _gathered.attribute
__dir__ = _gathered.listing

__all__ = [
    "AnyLaunchDescriptionSource",
    "FrontendLaunchDescriptionSource",
    "InvalidLaunchFileError",
    "InvalidPythonLaunchFileError",
    "LaunchDescriptionSource",
    "PythonLaunchDescriptionSource",
    "XMLLaunchDescriptionSource",
    "YAMLLaunchDescriptionSource",
    "get_launch_description_from_python_launch_file",
    "load_python_launch_file_as_module",
]
