"""A simulated clock for `mlaunch test`'s use_sim_time check.

    mlaunch test tests/launches/sim_clock.launch.py use_sim_time:=true [frozen:=true]

Runs /sim_clock (sim_clock.py), which publishes /clock advancing, or stuck with frozen:=true.
"""

import os
import sys

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, OpaqueFunction
from launch_ros.actions import Node

PROGRAM = os.path.join(os.path.dirname(os.path.abspath(__file__)), "sim_clock.py")


def clock(context):
    frozen = context.launch_configurations["frozen"] == "true"
    return [
        Node(
            executable=sys.executable,
            arguments=[PROGRAM, *(["--frozen"] if frozen else [])],
            name="sim_clock",
            exec_name="sim_clock",
        )
    ]


def generate_launch_description():
    return LaunchDescription(
        [
            DeclareLaunchArgument("use_sim_time", default_value="false"),
            DeclareLaunchArgument("frozen", default_value="false", choices=["true", "false"]),
            OpaqueFunction(function=clock),
        ]
    )
