"""``launch_ros.actions.set_use_sim_time``, where upstream defines it."""

from mlaunch.launch_ros.actions import SetUseSimTime

__all__ = ["SetUseSimTime"]
