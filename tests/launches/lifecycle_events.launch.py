"""Lifecycle nodes driven by launch_ros's events, for mlaunch's lifecycle support.

- /robot/camera: autostart=True and respawn=True, so mlaunch configures and activates it, and
  does so again after it is killed and respawned.
- /robot/lidar: no autostart. When the camera first becomes active (OnStateTransition,
  handle_once), a ChangeState event configures the lidar; when the lidar reaches 'inactive',
  another ChangeState (matched by node name) activates it.
Both print `transition <name>: <result>` on stdout (output=screen) for the test to follow.
"""

import os
import sys

from launch import LaunchDescription
from launch.actions import EmitEvent, LogInfo, RegisterEventHandler
from launch.events import matches_action
from launch_ros.actions import LifecycleNode
from launch_ros.event_handlers import OnStateTransition
from launch_ros.events.lifecycle import ChangeState, matches_node_name

NODE = os.path.join(
    os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "nodes", "lifecycle_node.py"
)


def generate_launch_description():
    camera = LifecycleNode(
        executable=sys.executable,
        arguments=[NODE],
        name="camera",
        namespace="robot",
        exec_name="camera",
        output="screen",
        autostart=True,
        respawn=True,
        respawn_delay=0.5,
    )
    lidar = LifecycleNode(
        executable=sys.executable,
        arguments=[NODE],
        name="lidar",
        namespace="robot",
        exec_name="lidar",
        output="screen",
    )
    configure_lidar = RegisterEventHandler(
        OnStateTransition(
            target_lifecycle_node=camera,
            goal_state="active",
            handle_once=True,
            entities=[
                LogInfo(msg="camera is active: configuring the lidar"),
                EmitEvent(
                    event=ChangeState(lifecycle_node_matcher=matches_action(lidar), transition_id=1)
                ),
            ],
        )
    )
    activate_lidar = RegisterEventHandler(
        OnStateTransition(
            target_lifecycle_node=lidar,
            start_state="configuring",
            goal_state="inactive",
            entities=[
                LogInfo(msg="lidar is configured: activating it"),
                EmitEvent(
                    event=ChangeState(
                        lifecycle_node_matcher=matches_node_name("/robot/lidar"), transition_id=3
                    )
                ),
            ],
        )
    )
    return LaunchDescription([configure_lidar, activate_lidar, camera, lidar])
