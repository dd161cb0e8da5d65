# args: robot:=r2 mode:=fast
import sys

from launch import LaunchDescription
from launch.actions import LogInfo, OpaqueFunction


def generate_launch_description():
    # The layout some packages parse: `ros2 launch FILE args` puts the arguments at sys.argv[3:].
    given = [a for a in sys.argv[3:] if ":=" in a]
    return LaunchDescription(
        [
            LogInfo(msg="argv[1:] " + " ".join(sys.argv[1:])),
            LogInfo(msg="arguments " + " ".join(given)),
            OpaqueFunction(
                function=lambda context: [LogInfo(msg="later " + " ".join(sys.argv[1:]))]
            ),
        ]
    )
