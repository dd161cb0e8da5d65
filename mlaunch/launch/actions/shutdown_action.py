"""``launch.actions.shutdown_action``: shut the launch down."""

from __future__ import annotations

from mlaunch.launch.action import Action
from mlaunch.launch.emission import emit_event_entities
from mlaunch.launch.substitution import normalize, perform_substitutions

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext
    from mlaunch.launch.substitution import SomeSubstitutionsType


class Shutdown(Action):
    """Shut the launch down (what ``on_exit=Shutdown()`` uses to make a process required)."""

    def __init__(self, *, reason: SomeSubstitutionsType = "reason not given", **kwargs: Any):
        super().__init__(**kwargs)
        self.reason = normalize(reason)

    def execute(self, context: LaunchContext) -> None:
        from mlaunch.launch.events.shutdown import Shutdown as ShutdownEvent

        reason = perform_substitutions(context, self.reason)
        emit_event_entities(context, ShutdownEvent(reason=reason), self.origin)
