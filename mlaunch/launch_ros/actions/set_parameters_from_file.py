"""``launch_ros.actions.set_parameters_from_file``: a params file for the nodes after it."""

from __future__ import annotations

from mlaunch.launch.action import Action
from mlaunch.launch.substitution import (
    SomeSubstitutionsType,
    describe,
    normalize,
    perform_substitutions,
)
from mlaunch.launch_ros.scope import (
    add_global_params,
    note_params_file_origin,
)

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext


class SetParametersFromFile(Action):
    """A params file for every node after it in this scope (``--params-file``)."""

    def __init__(self, filename: SomeSubstitutionsType, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.filename = normalize(filename)

    def execute(self, context: LaunchContext) -> None:
        # As given, as launch_ros keeps it: a node after it looks the file up (relative to the
        # working directory) and, when it is missing, names this line.
        filename = perform_substitutions(context, self.filename)
        note_params_file_origin(context, filename, self.origin)
        add_global_params(context, self, (filename,))

    def describe_short(self) -> str:
        return f"SetParametersFromFile({describe(self.filename)})"
