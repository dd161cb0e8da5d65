"""``launch_ros.substitutions``: package lookups and the global-parameter substitution.

Each lives in its own module, named as upstream's; this package only gathers the names
(``mlaunch.launch.gathering``). Importing this package registers the in-process xacro for
``Command(['xacro ', ...])``, as it always did.
"""

from __future__ import annotations

from mlaunch.launch.gathering import Gathered
from mlaunch.launch_ros import xacro as _xacro

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.launch_ros.substitutions.executable_in_package import ExecutableInPackage
    from mlaunch.launch_ros.substitutions.find_package import (
        FindPackage,
        FindPackagePrefix,
        FindPackageShare,
    )
    from mlaunch.launch_ros.substitutions.parameter import Parameter

_gathered = Gathered(
    globals(),
    {
        "ExecutableInPackage": ".executable_in_package",
        "FindPackage": ".find_package",
        "FindPackagePrefix": ".find_package",
        "FindPackageShare": ".find_package",
        "Parameter": ".parameter",
    },
    submodules=("executable_in_package", "find_package", "parameter"),
)
__getattr__ = _gathered.attribute
__dir__ = _gathered.listing

_xacro.register()

__all__ = [
    "ExecutableInPackage",
    "FindPackage",
    "FindPackagePrefix",
    "FindPackageShare",
    "Parameter",
]
