"""``launch_ros.actions.set_parameters_from_file``, where upstream defines it."""

from mlaunch.launch_ros.actions import SetParametersFromFile

__all__ = ["SetParametersFromFile"]
