"""``launch_ros.substitutions.find_package``: a package's prefix or share folder.

Lookups go through mlaunch.ros.packages: installed packages of ``AMENT_PREFIX_PATH`` (from the
launch context's environment) first, then source packages near the launch file.
"""

from __future__ import annotations

from mlaunch.launch.substitution import (
    SomeSubstitutionsType,
    Substitution,
    describe,
    normalize,
    perform_substitutions,
)
from mlaunch.launch.substitutions.path_join_substitution import PathJoinSubstitution
from mlaunch.ros import packages

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.launch.launch_context import LaunchContext


class FindPackage(Substitution):
    """Base of the package lookups: ``find(package_name)`` names the directory wanted."""

    def __init__(self, package: SomeSubstitutionsType) -> None:
        self.package = normalize(package)

    def find(self, package_name: str) -> str:
        """The directory for a package, outside any launch context (launch-file code)."""
        return self.directory(packages.index(from_callers=True).get(package_name))

    def directory(self, package: packages.Package) -> str:
        raise NotImplementedError

    def perform(self, context: LaunchContext) -> str:
        name = perform_substitutions(context, self.package)
        if type(self).find is not FindPackage.find:  # a launch file's subclass overrides find()
            return self.find(name)
        return self.directory(packages.for_context(context).get(name))

    def __truediv__(self, other: SomeSubstitutionsType) -> PathJoinSubstitution:
        """``FindPackageShare('pkg') / 'launch' / 'x.launch.py'``, as in newer launch_ros."""
        return PathJoinSubstitution([self, other])

    def describe(self) -> str:
        return f"{type(self).__name__}(pkg={describe(self.package)})"


class FindPackagePrefix(FindPackage):
    """The install prefix of a package (``$(find-pkg-prefix pkg)``); a source package's folder."""

    def directory(self, package: packages.Package) -> str:
        return package.prefix


class FindPackageShare(FindPackage):
    """The share directory of a package (``$(find-pkg-share pkg)``); a source package's folder."""

    def directory(self, package: packages.Package) -> str:
        return package.share_directory
