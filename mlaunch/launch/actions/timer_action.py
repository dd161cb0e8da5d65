"""``launch.actions.timer_action``, where upstream defines it."""

from mlaunch.launch.actions import TimerAction

__all__ = ["TimerAction"]
