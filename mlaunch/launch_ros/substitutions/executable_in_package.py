"""``launch_ros.substitutions.executable_in_package``: the path of a package's executable."""

from __future__ import annotations

from mlaunch.launch.substitution import (
    SomeSubstitutionsType,
    describe,
    normalize,
    perform_substitutions,
)
from mlaunch.launch_ros.substitutions.find_package import FindPackagePrefix
from mlaunch.ros import packages

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.launch.launch_context import LaunchContext


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
