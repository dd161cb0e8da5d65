"""``ROSTimer`` (``RosTimer``): launch_ros's timer action, counted in ROS time.

launch_ros counts the period on the clock of launch's own ROS node: system time, or simulated
time once SetUseSimTime(True) has set use_sim_time on that node (anywhere in the launch, before
or after the timer: the node's clock follows /clock from then on). mlaunch records SetUseSimTime
in the run's ROS clock (``mlaunch.plan.steps.RosClock``) and the engine asks it when it starts
the timer: on system time the period is counted by the engine's own timers; on simulated time it
is handed to the ROS clock part (mlaunch.parts.ros_clock), which reads /clock.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from mlaunch.launch.actions.timer_action import TimerAction
from mlaunch.launch.substitution import SomeSubstitutionsType_types_tuple
from mlaunch.launch.utilities.ensure_argument_type_impl import ensure_argument_type
from mlaunch.plan.steps import RosClock, ros_clock


class ROSTimer(TimerAction):
    """Run ``actions`` once after ``period`` seconds of ROS time (see the module docstring)."""

    def __init__(self, *, period: float | Any, actions: Iterable[Any], **kwargs: Any) -> None:
        ensure_argument_type(
            period, [*SomeSubstitutionsType_types_tuple, float, int], "period", "ROSTimer"
        )
        ensure_argument_type(actions, Iterable, "actions", "ROSTimer")
        super().__init__(period=period, actions=actions, **kwargs)

    def _ros_clock(self, context: Any) -> RosClock:
        return ros_clock(context.run_state)


RosTimer = ROSTimer
