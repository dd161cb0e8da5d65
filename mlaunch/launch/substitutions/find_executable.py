"""``launch.substitutions.find_executable``: the path of a program on PATH."""

from __future__ import annotations

import os

from mlaunch.launch.substitution import (
    SomeSubstitutionsType,
    Substitution,
    describe,
    normalize,
    perform_substitutions,
)
from mlaunch.plan.errors import SubstitutionFailure

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.launch.launch_context import LaunchContext


def which(name: str, path: str) -> str | None:
    """The first executable file ``name`` on ``path`` (shutil.which, without importing shutil)."""
    if os.sep in name:
        return name if os.access(name, os.X_OK) and not os.path.isdir(name) else None
    for folder in path.split(os.pathsep):
        candidate = os.path.join(folder or os.curdir, name)
        if os.access(candidate, os.X_OK) and not os.path.isdir(candidate):
            return candidate
    return None


class FindExecutable(Substitution):
    """The full path of a program on PATH (``$(find-exec name)``)."""

    def __init__(self, *, name: SomeSubstitutionsType) -> None:
        self.name = normalize(name)

    def perform(self, context: LaunchContext) -> str:
        name = perform_substitutions(context, self.name)
        found = which(name, context.environment.get("PATH", os.defpath))
        if found is None:
            raise SubstitutionFailure(f"executable {name!r} not found on the PATH")
        return found

    def describe(self) -> str:
        return f"FindExec({describe(self.name)})"
