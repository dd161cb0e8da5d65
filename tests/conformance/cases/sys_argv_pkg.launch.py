# pkg args: robot:=r2 mode:=fast
import sys

from launch import LaunchDescription
from launch.actions import LogInfo


def generate_launch_description():
    # `ros2 launch PKG FILE args`: the arguments start at sys.argv[4] (what e.g. some drivers read).
    return LaunchDescription(
        [
            LogInfo(msg="argv[1:] " + " ".join(sys.argv[1:])),
            LogInfo(msg="from 4: " + " ".join(sys.argv[4:])),
        ]
    )
