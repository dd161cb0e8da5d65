from launch import LaunchDescription
from launch.actions import LogInfo, TimerAction
from launch_ros.actions import Node


def generate_launch_description():
    return LaunchDescription(
        [
            TimerAction(period=0.3, actions=[LogInfo(msg="second timer")]),
            TimerAction(
                period=0.1,
                actions=[
                    LogInfo(msg="first timer"),
                    Node(package="conf_pkg", executable="recorder", name="timed"),
                ],
            ),
            TimerAction(
                period="0.5",
                actions=[TimerAction(period=0.1, actions=[LogInfo(msg="nested timer")])],
            ),
            LogInfo(msg="no timer"),
        ]
    )
