"""``launch_ros.actions.set_remap``: a remap rule for the nodes after it."""

from __future__ import annotations

from mlaunch.launch.action import Action
from mlaunch.launch.substitution import (
    SomeSubstitutionsType,
    describe,
    normalize,
    perform_substitutions,
)
from mlaunch.launch_ros.scope import (
    add_global_remap,
)

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext


class SetRemap(Action):
    """A remapping for every node after it in this scope (``-r from:=to``)."""

    def __init__(self, src: SomeSubstitutionsType, dst: SomeSubstitutionsType, **kwargs: Any):
        super().__init__(**kwargs)
        self.src = normalize(src)
        self.dst = normalize(dst)

    # mlaunch's: True keeps it inside a scoped group even without --scoped-parameters.
    keep_in_scope = False

    def execute(self, context: LaunchContext) -> None:
        rule = (perform_substitutions(context, self.src), perform_substitutions(context, self.dst))
        add_global_remap(context, self, rule)

    def describe_short(self) -> str:
        return f"SetRemap({describe(self.src)} -> {describe(self.dst)})"
