"""``launch.event_handlers.on_include_launch_description``: visits the description an
IncludeLaunchDescription event carries.
"""

from __future__ import annotations

from mlaunch.launch.event_handler import EventHandler

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any


class OnIncludeLaunchDescription(EventHandler):
    """Visits the description an IncludeLaunchDescription event carries."""

    def __init__(self, **kwargs: Any) -> None:
        from mlaunch.launch.events.include_launch_description import IncludeLaunchDescription

        super().__init__(
            matcher=lambda event: isinstance(event, IncludeLaunchDescription),
            entities=lambda event, context: [event.launch_description],
            **kwargs,
        )

    @property
    def handler_description(self) -> str:
        return "returns the launch_description in the event"

    @property
    def matcher_description(self) -> str:
        return "event issubclass of launch.events.IncludeLaunchDescription"
