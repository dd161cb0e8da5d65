"""``launch_ros.actions.push_ros_namespace``, where upstream defines it."""

from mlaunch.launch_ros.actions import PushROSNamespace

__all__ = ["PushROSNamespace"]
