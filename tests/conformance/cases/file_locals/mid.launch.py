from launch import LaunchDescription
from launch.actions import IncludeLaunchDescription, LogInfo
from launch.launch_description_sources import AnyLaunchDescriptionSource
from launch.substitutions import LaunchConfiguration, ThisLaunchFile, ThisLaunchFileDir


def generate_launch_description():
    return LaunchDescription(
        [
            LogInfo(msg=["mid from_top ", LaunchConfiguration("from_top")]),
            LogInfo(msg=["mid before ", ThisLaunchFileDir()]),
            IncludeLaunchDescription(
                AnyLaunchDescriptionSource([ThisLaunchFileDir(), "/deep/bot.launch.yaml"]),
                launch_arguments=[
                    ("first", ThisLaunchFileDir()),
                    ("second", LaunchConfiguration("first")),
                    ("file", ThisLaunchFile()),
                ],
            ),
            LogInfo(msg=["mid after ", ThisLaunchFileDir(), " ", ThisLaunchFile()]),
        ]
    )
