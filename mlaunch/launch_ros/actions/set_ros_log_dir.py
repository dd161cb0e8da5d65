"""``launch_ros.actions.set_ros_log_dir``: the ROS log folder of the nodes after it."""

from __future__ import annotations

import os
from collections.abc import Mapping

from mlaunch.launch.action import Action
from mlaunch.launch.substitution import (
    SomeSubstitutionsType,
    normalize,
    perform_substitutions,
)

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext


class SetROSLogDir(Action):
    """``ROS_LOG_DIR`` for processes started after it: absolute, or joined to the current one."""

    def __init__(self, new_log_dir: SomeSubstitutionsType, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.log_dir = normalize(new_log_dir)

    def execute(self, context: LaunchContext) -> None:
        new = perform_substitutions(context, self.log_dir)
        context.environment["ROS_LOG_DIR"] = os.path.join(ros_log_dir(context.environment), new)


SetRosLogDir = SetROSLogDir


def ros_log_dir(environ: Mapping[str, str]) -> str:
    """rcl's logging directory: ROS_LOG_DIR, else $ROS_HOME/log, else ~/.ros/log."""
    home = environ.get("HOME") or os.path.expanduser("~")
    explicit = environ.get("ROS_LOG_DIR")
    if explicit:
        return explicit.replace("~", home, 1) if explicit.startswith("~") else explicit
    ros_home = environ.get("ROS_HOME")
    if ros_home:
        ros_home = ros_home.replace("~", home, 1) if ros_home.startswith("~") else ros_home
        return os.path.join(ros_home, "log")
    return os.path.join(home, ".ros", "log")
