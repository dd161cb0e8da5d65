"""ros_gz_sim's gz_sim.launch.py for mlaunch's stand-ins: Gazebo Sim with ``gz_args``.

The same arguments as the package's own file (Jazzy). ``gz sim ARGS`` runs as the 2D simulator
stand-in (``gz sim -g`` alone, Gazebo's window, as the viewer stand-in); as in the real file, the
launch shuts down when it exits, and the model folders that packages export in their
package.xml (``<export><gazebo_ros gazebo_model_path="${prefix}/models"/>``) are added to
``GZ_SIM_RESOURCE_PATH``, so ``model://NAME`` in a world finds them.
"""

import os
import shlex
import xml.etree.ElementTree as ET

from ament_index_python.packages import get_packages_with_prefixes
from launch import LaunchContext, LaunchDescription
from launch.actions import DeclareLaunchArgument, ExecuteProcess, OpaqueFunction, Shutdown
from launch.substitutions import LaunchConfiguration

EXPORT_KEYS = ("gazebo_model_path", "gazebo_media_path")


def exported_model_paths() -> list[str]:
    """The model folders every package exports for Gazebo, in package order."""
    paths = []
    for name, prefix in sorted(get_packages_with_prefixes().items()):
        share = os.path.join(prefix, "share", name)
        if not os.path.isdir(share):  # a package checked out, not installed: its own folder
            share = prefix
        try:
            root = ET.parse(os.path.join(share, "package.xml")).getroot()
        except (OSError, ET.ParseError):
            continue
        for export in root.iter("gazebo_ros"):
            for key in EXPORT_KEYS:
                value = export.get(key)
                if value:
                    paths.append(value.replace("${prefix}", share))
    return paths


def start_gz(context: LaunchContext) -> list[ExecuteProcess]:
    gz_args = LaunchConfiguration("gz_args").perform(context)
    ign_args = LaunchConfiguration("ign_args").perform(context)
    words = shlex.split(gz_args if gz_args or not ign_args else ign_args)
    resource = os.pathsep.join(
        p
        for p in [context.environment.get("GZ_SIM_RESOURCE_PATH", ""), *exported_model_paths()]
        if p
    )
    return [
        ExecuteProcess(
            cmd=["gz", "sim", *words],
            name="gazebo",
            output="screen",
            additional_env={"GZ_SIM_RESOURCE_PATH": resource},
            on_exit=Shutdown(),
        )
    ]


def generate_launch_description() -> LaunchDescription:
    return LaunchDescription(
        [
            DeclareLaunchArgument("gz_args", default_value="", description="Arguments of gz sim"),
            DeclareLaunchArgument(
                "gz_version", default_value="8", description="Gazebo Sim's major version"
            ),
            DeclareLaunchArgument("ign_args", default_value="", description="Deprecated: gz_args"),
            DeclareLaunchArgument(
                "ign_version", default_value="", description="Deprecated: gz_version"
            ),
            DeclareLaunchArgument(
                "debugger",
                default_value="false",
                description="Run in a debugger (not with the stand-in)",
            ),
            DeclareLaunchArgument(
                "on_exit_shutdown", default_value="false", description="Shut down when gz sim exits"
            ),
            OpaqueFunction(function=start_gz),
        ]
    )
