"""``ROSTimer`` (``RosTimer``): launch_ros's timer action.

launch_ros counts the period on the ROS clock, which is simulated time under use_sim_time.
mlaunch's engine has wall-clock timers only: the period is counted in wall time, and the plan
warns when the launch set use_sim_time, where the two clocks differ.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from mlaunch.launch.actions import TimerAction
from mlaunch.launch.substitution import SomeSubstitutionsType_types_tuple
from mlaunch.launch.utilities import ensure_argument_type
from mlaunch.launch_ros.scope import global_params


class ROSTimer(TimerAction):
    """Run ``actions`` once after ``period`` seconds (see the module docstring for the clock)."""

    def __init__(self, *, period: float | Any, actions: Iterable[Any], **kwargs: Any) -> None:
        ensure_argument_type(
            period, [*SomeSubstitutionsType_types_tuple, float, int], "period", "ROSTimer"
        )
        ensure_argument_type(actions, Iterable, "actions", "ROSTimer")
        super().__init__(period=period, actions=actions, **kwargs)

    def execute(self, context: Any) -> None:
        if _sim_time(context):
            context.planner.warn(
                f"{self.origin}: ROSTimer counts its period in wall-clock time under mlaunch;"
                " this launch sets use_sim_time, where ROS time may run at another pace"
            )
        super().execute(context)


def _sim_time(context: Any) -> bool:
    for entry in global_params(context):
        name, value = entry if isinstance(entry, tuple) and len(entry) == 2 else (None, None)
        if name == "use_sim_time" and str(value).lower() == "true":
            return True
    return False


RosTimer = ROSTimer
