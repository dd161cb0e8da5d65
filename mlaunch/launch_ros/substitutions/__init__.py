"""``launch_ros.substitutions``: package lookups and the global-parameter substitution.

Lookups go through mlaunch.ros.packages: installed packages of ``AMENT_PREFIX_PATH`` (from the
launch context's environment) first, then source packages near the launch file.
Importing this module registers the in-process xacro for ``Command(['xacro ', ...])``.
"""

from __future__ import annotations

import collections.abc

from mlaunch.launch.substitutions import (
    PathJoinSubstitution,
    SomeSubstitutionsType,
    Substitution,
    describe,
    normalize,
    perform_substitutions,
)
from mlaunch.launch_ros import xacro as _xacro
from mlaunch.plan.errors import SubstitutionFailure
from mlaunch.ros import packages

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext

_xacro.register()


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


class ExecutableInPackage(FindPackagePrefix):
    """``<prefix>/lib/<package>/<executable>`` (``$(exec-in-pkg exe pkg)``)."""

    def __init__(self, executable: SomeSubstitutionsType, package: SomeSubstitutionsType) -> None:
        super().__init__(package)
        self.executable = normalize(executable)

    def perform(self, context: LaunchContext) -> str:
        executable = perform_substitutions(context, self.executable)
        package = perform_substitutions(context, self.package)
        return packages.for_context(context).executable(package, executable)

    def describe(self) -> str:
        return f"ExecInPkg(pkg={describe(self.package)}, exec={describe(self.executable)})"


class Parameter(Substitution):
    """The value a SetParameter in scope gave a global parameter (``$(param name [default])``)."""

    def __init__(self, name: SomeSubstitutionsType, *, default: Any = None) -> None:
        self.name = normalize(name)
        self.default = None if default is None else normalize(_default_items(default))

    def perform(self, context: LaunchContext) -> str:
        name = perform_substitutions(context, self.name)
        for entry in context.launch_configurations.get("global_params", ()):
            if isinstance(entry, tuple) and entry[0] == name:
                return str(entry[1])
        if self.default is None:
            raise SubstitutionFailure(
                f"parameter {name!r} not found (set it with SetParameter / <set_parameter>"
                " before this point, or give a default)"
            )
        return perform_substitutions(context, self.default)

    def describe(self) -> str:
        return f"Parameter(name={describe(self.name)})"


def _default_items(default: Any) -> list[Any]:
    """launch_ros turns every default item that is not text or a substitution into str()."""
    items = default if isinstance(default, collections.abc.Iterable) else (default,)
    if isinstance(default, str):
        items = (default,)
    return [i if isinstance(i, (str, Substitution)) else str(i) for i in items]


__all__ = [
    "ExecutableInPackage",
    "FindPackage",
    "FindPackagePrefix",
    "FindPackageShare",
    "Parameter",
]
