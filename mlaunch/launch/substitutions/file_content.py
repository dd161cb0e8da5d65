"""``launch.substitutions.file_content``: the text of a file."""

from __future__ import annotations

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


class FileContent(Substitution):
    """The text of a file (``$(file-content path)``)."""

    def __init__(self, path: SomeSubstitutionsType) -> None:
        self.path = normalize(path)

    def perform(self, context: LaunchContext) -> str:
        path = perform_substitutions(context, self.path)
        try:
            with open(path, encoding="utf-8") as f:
                return f.read()
        except FileNotFoundError:
            raise SubstitutionFailure(f"File not found: {path}")
        except OSError as e:
            raise SubstitutionFailure(f"cannot read file {path!r}: {e.strerror}")

    def describe(self) -> str:
        return f"FileContent({describe(self.path)})"
