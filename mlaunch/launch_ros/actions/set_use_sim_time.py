"""``launch_ros.actions.set_use_sim_time``: ``use_sim_time`` for the nodes after it (and simulated
time for ROSTimer).
"""

from __future__ import annotations

from mlaunch.launch.action import Action
from mlaunch.launch_ros.parameter_descriptions import normalize_typed, perform_typed
from mlaunch.plan.steps import ros_clock

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext


class SetUseSimTime(Action):
    """``use_sim_time`` of launch's own ROS clock (ROSTimer), as in Jazzy.

    As in launch_ros (Jazzy), this does NOT set use_sim_time on the nodes; the value is kept
    in the launch configuration ``ros_use_sim_time`` and a warning points at the ways that do:
    ``SetParameter('use_sim_time', True)`` or ``mlaunch --use-sim-time``.
    """

    def __init__(self, value: Any, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.value = normalize_typed(value, bool)

    def execute(self, context: LaunchContext) -> None:
        planner = context.planner
        value = bool(perform_typed(context, self.value, bool))
        context.launch_configurations["ros_use_sim_time"] = value
        # launch's own ROS node is one per launch: not scoped (a ROSTimer reads it, run time).
        ros_clock(context.run_state).simulated = value
        planner.warn(
            f"{self.origin}: SetUseSimTime({value}) sets use_sim_time only for launch's own ROS"
            " clock, not for the nodes (as in ROS 2 Jazzy); use SetParameter('use_sim_time',"
            f" {value}) or mlaunch --use-sim-time for the nodes"
        )
