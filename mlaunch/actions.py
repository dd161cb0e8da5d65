"""mlaunch's own actions, beyond the ROS 2 names: ``from mlaunch.actions import Machine``.

They are written like launch's actions and mix with them in one LaunchDescription; a launch file
that uses them needs mlaunch (ros2 launch does not know them).
"""

from __future__ import annotations

from mlaunch.machines.actions import Machine, PushMachine

__all__ = ["Machine", "PushMachine"]
