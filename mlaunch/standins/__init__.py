"""Stand-ins: small rclpy programs that take the place of ROS programs that are not installed.

Each one accepts the real program's command line (including ROS arguments) and is run as
``python -m mlaunch.standins.<module> ARGS...``. They import rclpy inside their entry points only.
A real installation always wins: the resolver asks here only when the program is not found.
"""

from __future__ import annotations

import importlib.util
import os
import sys

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.plan.steps import ProcessSpec

# The stand-ins' shares: a folder per package whose launch files other launch files include
# (ros_gz_sim's gz_sim.launch.py, ...), found when the package is neither installed nor checked
# out (mlaunch.ros.packages.PackageIndex.standin_share). Their programs are the stand-ins below.
SHARE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "share")

# Programs found on PATH by name: name -> (module, how many leading argv items the stand-in
# replaces, the argv[1] the real program needs for this use, if any).
PROGRAMS: dict[str, tuple[str, int, str | None]] = {
    "gazebo": ("sim", 1, None),
    "gzserver": ("sim", 1, None),
    "gz": ("sim", 1, "sim"),
    "ign": ("sim", 1, "gazebo"),
    "rviz2": ("viewer", 1, None),
    "spawn_entity.py": ("spawn", 0, None),
}

# Executables of ROS packages: (package, executable) -> (module, argv items to put first).
PACKAGE_EXECUTABLES: dict[tuple[str, str], tuple[str, tuple[str, ...]]] = {
    ("robot_state_publisher", "robot_state_publisher"): ("rsp", ()),
    ("joint_state_publisher", "joint_state_publisher"): ("jsp", ()),
    ("joint_state_publisher_gui", "joint_state_publisher_gui"): ("jsp", ()),
    ("rviz2", "rviz2"): ("viewer", ()),
    ("gazebo_ros", "spawn_entity.py"): ("spawn", ("spawn_entity.py",)),
    ("ros_gz_sim", "create"): ("spawn", ("create",)),
    ("ros_gz_bridge", "parameter_bridge"): ("gz_bridge", ("parameter_bridge",)),
    ("ros_gz_bridge", "bridge_node"): ("gz_bridge", ("bridge_node",)),
    ("ros_gz_image", "image_bridge"): ("gz_bridge", ("image_bridge",)),
    ("gazebo_ros", "gzserver"): ("sim", ()),
    ("tf2_ros", "static_transform_publisher"): ("stp", ()),
    ("rclcpp_components", "component_container"): ("container", ()),
    ("rclcpp_components", "component_container_mt"): ("container", ()),
    ("rclcpp_components", "component_container_isolated"): ("container", ()),
}

# What a stand-in needs beyond rclpy: module -> the Python package that must be importable.
# tf2_msgs has no wheel on PyPI; scripts/setup builds it (interfaces/).
NEEDS: dict[str, str] = {"stp": "tf2_msgs", "container": "composition_interfaces"}


def rclpy_available() -> bool:
    return importlib.util.find_spec("rclpy") is not None


def _usable(module: str) -> bool:
    needs = NEEDS.get(module)
    return rclpy_available() and (needs is None or importlib.util.find_spec(needs) is not None)


def _module_argv(module: str) -> list[str]:
    return [sys.executable, "-m", f"mlaunch.standins.{module}"]


# The viewer stand-in (mlaunch.standins.viewer) prints its page's address as a line starting
# with this on stdout.
VIEWER_ADDRESS = b"viewer: open "


def equip(spec: ProcessSpec) -> None:
    """What a stand-in's process carries for the engine, through the spec's general seams: the
    viewer's address line is said by mlaunch in every output mode (``announce``), and its port
    is pinned before each start (``prepare``)."""
    if spec.standin is not None and list(spec.argv[:3]) == _module_argv("viewer"):
        spec.announce = VIEWER_ADDRESS
        spec.prepare = pin_viewer_port


def pin_viewer_port(spec: ProcessSpec) -> None:
    """Give a viewer stand-in that would take any free port a fixed free one, in its ``env``.

    The viewer picks a port when it starts; restarted (``mlaunch ctl restart``, respawn) it
    would pick another and the open tab would die. Chosen once here, the restarted viewer
    listens where the page already looks.
    """
    from mlaunch.standins.viewer_config import PORT_ENV

    if spec.env.get(PORT_ENV, "").strip() not in ("", "0"):
        return
    import socket

    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        spec.env[PORT_ENV] = str(probe.getsockname()[1])


def standin_for(argv: list[str]) -> list[str] | None:
    """The stand-in command line for a program not found on PATH, or None."""
    name = os.path.basename(argv[0])
    entry = PROGRAMS.get(name)
    if entry is None or not rclpy_available():
        return None
    module, consumed, needs = entry
    if needs is not None and (len(argv) < 2 or argv[1] != needs):
        return None
    if module == "spawn":
        return [*_module_argv(module), name, *argv[1:]]
    if name in ("gz", "ign") and _gui_only(argv[consumed:]):
        # `gz sim -g` is Gazebo's GUI alone, a client of the server another process runs:
        # the viewer is the stand-ins' window onto the simulation, not a second simulator.
        return _module_argv("viewer")
    return [*_module_argv(module), *argv[consumed:]]


def _gui_only(args: list[str]) -> bool:
    """A ``gz sim`` command line that starts only the GUI (``-g`` without ``-s``)."""
    return "-g" in args and "-s" not in args


def unmet_need(package: str, executable: str) -> str | None:
    """The Python package a stand-in for this executable needs and does not find, if any."""
    entry = PACKAGE_EXECUTABLES.get((package, executable))
    needs = None if entry is None else NEEDS.get(entry[0])
    if needs is None or importlib.util.find_spec(needs) is not None:
        return None
    return needs


def standin_for_package(package: str, executable: str) -> list[str] | None:
    """The argv items that replace ``<prefix>/lib/<package>/<executable>``, or None."""
    entry = PACKAGE_EXECUTABLES.get((package, executable))
    if entry is None or not _usable(entry[0]):
        return None
    module, first = entry
    return [*_module_argv(module), *first]


def hint_for(argv: list[str]) -> str:
    """A hint for the error when no stand-in was used."""
    name = os.path.basename(argv[0])
    if name in PROGRAMS:
        if not rclpy_available():
            return " (mlaunch's stand-in needs rclpy: pip install 'mlaunch[ros]')"
        return " (mlaunch has a stand-in for it: run without --no-standins)"
    return ""
