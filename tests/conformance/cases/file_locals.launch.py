# ros2/launch#618 in Jazzy: the locals stay the included file's after an include, timers too
import os

from launch import LaunchDescription
from launch.actions import IncludeLaunchDescription, LogInfo, TimerAction
from launch.launch_description_sources import AnyLaunchDescriptionSource
from launch.substitutions import ThisLaunchFileDir

HERE = os.path.dirname(__file__)


def generate_launch_description():
    return LaunchDescription(
        [
            IncludeLaunchDescription(
                AnyLaunchDescriptionSource(os.path.join(HERE, "file_locals", "mid.launch.yaml")),
                launch_arguments={"from_top": ThisLaunchFileDir()}.items(),
            ),
            LogInfo(msg=["top after ", ThisLaunchFileDir()]),
            TimerAction(period=0.2, actions=[LogInfo(msg=["top timer ", ThisLaunchFileDir()])]),
        ]
    )
