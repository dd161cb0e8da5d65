"""Gazebo plugin and sensor blocks of a URDF: names, ROS topic resolution, element values.

What every reader of ``<gazebo>`` blocks shares (the diff drive, the sensors, the camera): the
plugin library names, the error type, gazebo_ros's topic resolution (``<ros><namespace>`` and
``<remapping>``) and typed element values with errors that name the element and the bad text.
Pure Python; never imports rclpy.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass

from mlaunch.plan.errors import StandinError

# Plugin file names, with and without the lib prefix / .so suffix (gz accepts both spellings).
CLASSIC_DIFF_DRIVE = "gazebo_ros_diff_drive"
CLASSIC_JOINT_STATES = "gazebo_ros_joint_state_publisher"
CLASSIC_RAY = "gazebo_ros_ray_sensor"
CLASSIC_IMU = "gazebo_ros_imu_sensor"
GZ_DIFF_DRIVE = ("gz-sim-diff-drive-system", "ignition-gazebo-diff-drive-system")
GZ_JOINT_STATES = (
    "gz-sim-joint-state-publisher-system",
    "ignition-gazebo-joint-state-publisher-system",
)
LIDAR_TYPES = ("ray", "gpu_ray", "lidar", "gpu_lidar")
IMU_TYPES = ("imu",)
# Joint states are published at this rate when no joint state plugin says otherwise.
DEFAULT_JOINT_STATE_RATE = 50.0


class ModelError(StandinError, ValueError):
    """A plugin or sensor block the simulator cannot use; the message names it and the value."""


def plugin_kind(filename: str) -> str:
    """The plugin's library name without ``lib`` prefix and ``.so`` suffix."""
    name = filename.strip().rsplit("/", 1)[-1]
    name = name.removesuffix(".so")
    return name.removeprefix("lib")


# ---------------------------------------------------------------- ROS names


def expand_topic(name: str, namespace: str, node: str) -> str:
    """A topic name made absolute the ROS 2 way: ``~`` is the node, relative joins the namespace."""
    ns = "/" + namespace.strip("/") if namespace.strip("/") else ""
    if name == "~" or name.startswith("~/"):
        return f"{ns}/{node}{name[1:]}"
    if name.startswith("/"):
        return name
    return f"{ns}/{name}"


@dataclass(frozen=True)
class RosNames:
    """A gazebo_ros plugin's node: its namespace, name and remappings, for resolving topics."""

    namespace: str = "/"
    node: str = "gazebo_plugin"
    remaps: tuple[tuple[str, str], ...] = ()

    def resolve(self, name: str) -> str:
        """The absolute topic ``name`` ends up on, after the first matching remapping."""
        full = expand_topic(name, self.namespace, self.node)
        for source, target in self.remaps:
            if expand_topic(source, self.namespace, self.node) == full:
                return expand_topic(target, self.namespace, self.node)
        return full


def parse_ros_block(plugin: ET.Element, robot_namespace: str = "") -> RosNames:
    """Read ``<ros><namespace>/<remapping>/<argument>`` of a gazebo_ros plugin.

    ``robot_namespace`` (spawn_entity's -robot_namespace) replaces every plugin's namespace, as
    spawn_entity.py rewrites the ``<namespace>`` elements before handing the model to Gazebo.
    """
    ros = plugin.find("ros")
    namespace = ""
    remaps: list[tuple[str, str]] = []
    if ros is not None:
        namespace = (ros.findtext("namespace") or "").strip()
        rules = [(e.text or "").strip() for e in ros.findall("remapping")]
        rules += [(e.text or "").strip() for e in ros.findall("argument")]
        for rule in rules:
            if ":=" not in rule:
                continue  # e.g. "--ros-args" or "-r" in the older <argument> spelling
            source, target = (part.strip() for part in rule.split(":=", 1))
            if source == "__ns":
                namespace = target
            elif source and target and not source.startswith("__"):
                remaps.append((source, target))
    if robot_namespace:
        namespace = robot_namespace
    node = plugin.get("name") or plugin_kind(plugin.get("filename", "plugin"))
    return RosNames("/" + namespace.strip("/"), node, tuple(remaps))


# ---------------------------------------------------------------- element values


def where_of(plugin: ET.Element) -> str:
    return f"plugin {plugin.get('name', '?')!r} ({plugin.get('filename', '?')})"


def read_float(holder: ET.Element, tag: str, default: float, where: str) -> float:
    text = holder.findtext(tag)
    if text is None or not text.strip():
        return default
    try:
        value = float(text)
    except ValueError:
        raise ModelError(f"{where}: <{tag}> is {text.strip()!r}, not a number") from None
    if not math.isfinite(value):
        raise ModelError(f"{where}: <{tag}> is {text.strip()!r}, not a finite number")
    return value


def read_int(holder: ET.Element, tag: str, default: int, where: str) -> int:
    value = read_float(holder, tag, float(default), where)
    if value != int(value) or value < 0:
        raise ModelError(
            f"{where}: <{tag}> is {holder.findtext(tag)!r}, expected a whole number >= 0"
        )
    return int(value)


def read_bool(holder: ET.Element, tag: str, default: bool, where: str) -> bool:
    text = holder.findtext(tag)
    if text is None or not text.strip():
        return default
    value = text.strip().lower()
    if value in ("true", "1"):
        return True
    if value in ("false", "0"):
        return False
    raise ModelError(f"{where}: <{tag}> is {text.strip()!r}; expected true or false")


def read_text(holder: ET.Element, tag: str, default: str) -> str:
    text = holder.findtext(tag)
    return text.strip() if text is not None and text.strip() else default


def positive(value: float, what: str, where: str) -> float:
    if value <= 0:
        raise ModelError(f"{where}: {what} is {value!r}; it must be positive")
    return value
