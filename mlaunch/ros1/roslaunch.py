"""The ROS 1 frontend: a roslaunch XML file (``*.launch``) run on ROS 2 semantics.

Reading goes in two steps, and ``mlaunch convert`` shares the first one:

1. ``read(path)`` (``mlaunch.ros1.reading``) parses the XML and *maps* it to a small model of
   the ROS 2 launch description it becomes (``mlaunch.ros1.model``). Every ROS 1 -> ROS 2
   decision is taken there, once (docs/ros1.md lists them); the nodes of known ROS 1 packages
   are rewritten by the table in ``mlaunch.ros1.mapping``.
2. ``to_actions(items)`` (``mlaunch.ros1.build``) builds that model into mlaunch's own actions
   (the ROS 2 classes); ``mlaunch.commands.convert`` writes the same model out as a ROS 2 launch
   file instead. Running the ROS 1 file and running its conversion therefore resolve to the
   same plan.

What has no ROS 2 equivalent becomes a warning naming the file and line: a warning action in
the description (so ``--print`` and runs show it) and a comment in a converted file.
"""

from __future__ import annotations

import os
from typing import Any

from mlaunch.ros1.build import description_actions
from mlaunch.ros1.reading import read


def load(path: str) -> Any:
    """The LaunchDescription of the roslaunch XML file at ``path``."""
    from mlaunch.launch.launch_description import LaunchDescription

    description = LaunchDescription(description_actions(os.path.abspath(path), read(path)))
    description.origin = f"{os.path.abspath(path)}:1"
    return description


__all__ = ["load", "read"]
