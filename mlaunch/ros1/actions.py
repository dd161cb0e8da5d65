"""The actions a roslaunch file adds to mlaunch's ROS 2 ones where roslaunch's rules differ.

An ``<include>`` of a roslaunch file reads roslaunch XML whatever the suffix; an untyped
``<param value>`` with substitutions is typed by roslaunch's rule; a node's ``args`` with
substitutions is substituted first, then split like a shell.
"""

from __future__ import annotations

import shlex
from typing import TYPE_CHECKING, Any

from mlaunch.launch.launch_description_sources import AnyLaunchDescriptionSource
from mlaunch.launch.substitutions import TextSubstitution, normalize, perform_substitutions
from mlaunch.launch_ros.node import Node
from mlaunch.launch_ros.parameter_descriptions import ParameterValue
from mlaunch.plan.errors import MlaunchError
from mlaunch.ros1.values import convert_value

if TYPE_CHECKING:
    from mlaunch.launch.launch_context import LaunchContext
    from mlaunch.launch_ros.node import NodeCommand


class RoslaunchSource(AnyLaunchDescriptionSource):
    """A file a roslaunch file includes: roslaunch XML whatever its suffix, as roslaunch reads
    it (ROS 1 packages name their fragments ``*.launch.xml``)."""

    format_hint = "roslaunch"


class RoslaunchValue(ParameterValue):
    """An untyped ``<param value>`` with substitutions, typed as roslaunch types it: int,
    float, bool (true/false, any case), else text (``[*]`` stays text)."""

    def evaluate(self, context: LaunchContext) -> Any:
        text = perform_substitutions(context, self._value)
        self._evaluated = convert_value(text.strip(), "auto")
        return self._evaluated


class RoslaunchNode(Node):
    """A ROS 1 node whose ``args`` has substitutions: substituted first, then split like a
    shell, as roslaunch does (an argument that substitutes to nothing disappears)."""

    def __init__(self, *, shell_args: Any, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.shell_args = normalize(shell_args)

    def node_command(self, context: LaunchContext, *, remote: bool = False) -> NodeCommand:
        text = perform_substitutions(context, self.shell_args)
        try:
            words = shlex.split(text)
        except ValueError as e:
            raise MlaunchError(f"node args {text!r} cannot be split like a shell: {e}")
        self.arguments = [(TextSubstitution(text=w),) for w in words]
        return super().node_command(context, remote=remote)
