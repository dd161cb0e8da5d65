"""The robot's sensors the simulator serves: ray sensors (LaserScan) and IMUs, where they sit.

Each ``<sensor>`` of a ``<gazebo reference=LINK>`` block is read with its gazebo_ros plugin (or
its gz topic) into a frozen dataclass the simulator publishes from. Pure Python.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass

from mlaunch.standins.plugins import (
    CLASSIC_IMU,
    CLASSIC_RAY,
    ModelError,
    expand_topic,
    parse_ros_block,
    plugin_kind,
    read_bool,
    read_float,
    read_int,
    read_text,
)
from mlaunch.standins.world import GaussianNoise, ScanGeometry


@dataclass(frozen=True)
class Mount:
    """Where a sensor sits in the robot's root frame (seen from above), and its height."""

    x: float = 0.0
    y: float = 0.0
    z: float = 0.0
    yaw: float = 0.0
    upside_down: bool = False


@dataclass(frozen=True)
class LidarParams:
    """A ray sensor published as sensor_msgs/LaserScan."""

    name: str
    link: str
    mount: Mount
    update_rate: float
    scan: ScanGeometry
    noise: GaussianNoise
    topic: str
    frame_id: str


@dataclass(frozen=True)
class ImuParams:
    """An IMU sensor published as sensor_msgs/Imu."""

    name: str
    link: str
    mount: Mount
    update_rate: float
    angular_velocity: tuple[GaussianNoise, GaussianNoise, GaussianNoise]
    linear_acceleration: tuple[GaussianNoise, GaussianNoise, GaussianNoise]
    topic: str
    frame_id: str
    initial_orientation_as_reference: bool = False


def parse_noise(element: ET.Element | None, where: str) -> GaussianNoise:
    """``<noise type="gaussian"><mean><stddev><bias_mean><bias_stddev>`` (or ``<type>`` child)."""
    if element is None:
        return GaussianNoise()
    kind = (element.get("type") or element.findtext("type") or "gaussian").strip()
    if kind == "none":
        return GaussianNoise()
    if kind not in ("gaussian", "gaussian_quantized"):
        raise ModelError(f"{where}: noise type {kind!r} is not supported; use gaussian or none")
    return GaussianNoise(
        read_float(element, "mean", 0.0, where),
        abs(read_float(element, "stddev", 0.0, where)),
        read_float(element, "bias_mean", 0.0, where),
        abs(read_float(element, "bias_stddev", 0.0, where)),
    )


def parse_lidar(sensor: ET.Element, link: str, mount: Mount, robot_namespace: str) -> LidarParams:
    """A ``<sensor type="ray|gpu_ray|lidar|gpu_lidar">`` and its gazebo_ros plugin (or gz topic)."""
    name = sensor.get("name", "lidar")
    where = f"sensor {name!r} on link {link!r}"
    ray = sensor.find("ray")
    if ray is None:
        ray = sensor.find("lidar")
    if ray is None:
        raise ModelError(f"{where}: has no <ray> (or <lidar>) element with the scan settings")
    horizontal = ray.find("scan/horizontal")
    if horizontal is None:
        raise ModelError(f"{where}: has no <scan><horizontal> element")
    samples = read_int(horizontal, "samples", 640, where)
    if samples < 1:
        raise ModelError(f"{where}: <samples> is {samples}; a scan needs at least one ray")
    scan = ScanGeometry(
        angle_min=read_float(horizontal, "min_angle", 0.0, where),
        angle_max=read_float(horizontal, "max_angle", 0.0, where),
        samples=samples,
        range_min=read_float(ray, "range/min", 0.0, where),
        range_max=read_float(ray, "range/max", 0.0, where),
    )
    if scan.range_max <= scan.range_min or scan.range_min < 0:
        raise ModelError(
            f"{where}: range min {scan.range_min} / max {scan.range_max}; need 0 <= min < max"
        )
    plugin = sensor_plugin(sensor, CLASSIC_RAY)
    if plugin is not None:
        output = read_text(plugin, "output_type", "sensor_msgs/LaserScan")
        if output.replace("/msg/", "/") != "sensor_msgs/LaserScan":
            raise ModelError(
                f"{where}: <output_type> {output!r} is not simulated; only sensor_msgs/LaserScan"
            )
        topic = parse_ros_block(plugin, robot_namespace).resolve("~/out")
        frame = read_text(plugin, "frame_name", link)
    else:
        topic = expand_topic(read_text(sensor, "topic", "scan"), robot_namespace or "/", name)
        frame = read_text(sensor, "gz_frame_id", read_text(sensor, "frame_id", link))
    return LidarParams(
        name=name,
        link=link,
        mount=mount,
        update_rate=read_float(sensor, "update_rate", 0.0, where),
        scan=scan,
        noise=parse_noise(ray.find("noise"), where),
        topic=topic,
        frame_id=frame,
    )


def parse_imu(sensor: ET.Element, link: str, mount: Mount, robot_namespace: str) -> ImuParams:
    """A ``<sensor type="imu">`` with per-axis noise, and its gazebo_ros plugin (or gz topic)."""
    name = sensor.get("name", "imu")
    where = f"sensor {name!r} on link {link!r}"
    imu = sensor.find("imu")

    def axes(kind: str) -> tuple[GaussianNoise, GaussianNoise, GaussianNoise]:
        block = None if imu is None else imu.find(kind)
        found = [None if block is None else block.find(f"{axis}/noise") for axis in "xyz"]
        x, y, z = (parse_noise(e, f"{where} {kind}") for e in found)
        return (x, y, z)

    plugin = sensor_plugin(sensor, CLASSIC_IMU)
    reference = False
    if plugin is not None:
        topic = parse_ros_block(plugin, robot_namespace).resolve("~/out")
        frame = read_text(plugin, "frame_name", link)
        reference = read_bool(plugin, "initial_orientation_as_reference", False, where)
    else:
        topic = expand_topic(read_text(sensor, "topic", "imu"), robot_namespace or "/", name)
        frame = read_text(sensor, "gz_frame_id", read_text(sensor, "frame_id", link))
    return ImuParams(
        name=name,
        link=link,
        mount=mount,
        update_rate=read_float(sensor, "update_rate", 0.0, where),
        angular_velocity=axes("angular_velocity"),
        linear_acceleration=axes("linear_acceleration"),
        topic=topic,
        frame_id=frame,
        initial_orientation_as_reference=reference,
    )


def sensor_plugin(sensor: ET.Element, kind: str) -> ET.Element | None:
    for plugin in sensor.findall("plugin"):
        if plugin_kind(plugin.get("filename", "")) == kind:
            return plugin
    return None
