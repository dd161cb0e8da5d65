"""``launch.event_handlers.on_action_event_base``: the base of the handlers of one action's
events (mlaunch's EventHandler, which takes a target action).
"""

from __future__ import annotations

from mlaunch.launch.event_handler import EventHandler

OnActionEventBase = EventHandler
