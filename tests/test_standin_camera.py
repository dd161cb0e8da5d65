"""The simulator's depth camera: settings from the URDF, depth images ray-cast against the world.

The renderer is checked against a wall at a known distance (pure, numpy), the jtbot camera's
settings against its xacro, and the whole path (simulator process, spawned robot, a subscriber)
on a depth image whose pixels read the distance to the test world's wall.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from conftest import requires_rclpy
from test_robot_descriptions import JTBOT_XACRO, process
from test_standin_sim import URDF, WALL_FACE, Sim, sim_factory, spawn, world_file

from mlaunch.standins.camera import CameraParams, DepthRenderer
from mlaunch.standins.diffdrive import describe_model
from mlaunch.standins.sensors import Mount
from mlaunch.standins.shapes import Polygon
from mlaunch.standins.urdf import parse_urdf

__all__ = ["sim_factory", "world_file"]  # fixtures, used by name

# A wall 0.2 thick whose near face is 2.9 ahead of the origin, 4 wide and 1 high.
WALL = Polygon("wall", ((2.9, -2.0), (3.1, -2.0), (3.1, 2.0), (2.9, 2.0)), 0.0, 1.0)


def camera(encoding: str = "32FC1", width: int = 64, height: int = 48) -> CameraParams:
    return CameraParams(
        name="cam",
        link="camera_link",
        mount=Mount(),
        update_rate=10.0,
        width=width,
        height=height,
        hfov=1.0,
        near=0.05,
        far=5.0,
        min_depth=0.5,
        max_depth=4.0,
        encoding=encoding,
        frame_id="camera_optical",
        depth_topic="/cam/depth/image_raw",
        depth_info_topic="/cam/depth/camera_info",
        points_topic="/cam/points",
    )


def test_a_flat_wall_reads_its_distance_in_every_pixel_that_sees_it() -> None:
    params = camera()
    renderer = DepthRenderer(params, [WALL])
    z = 0.3
    depth = renderer.render(0.0, 0.0, z, 0.0)
    assert depth.shape == (48, 64) and depth.dtype == np.float32
    b = renderer.b
    # Rows whose line of sight meets the wall between its foot and its top (and not the ground
    # first) read the wall's distance along the optical axis: 2.9 wherever the column is.
    wall_rows = [v for v in range(48) if 0.0 <= z - b[v] * WALL_FACE <= 1.0]
    assert wall_rows, "the wall is in view"
    assert np.allclose(depth[wall_rows, :], WALL_FACE, atol=1e-5)
    # Rows looking down more steeply see the ground at z / b first; rows above the wall's top
    # see nothing within the far clip.
    for v in range(48):
        if b[v] > 0 and z / b[v] < WALL_FACE:
            assert depth[v, 0] == pytest.approx(z / b[v], abs=1e-5)
        elif z - b[v] * WALL_FACE > 1.0:
            assert depth[v, 0] == np.inf


def test_encodings_and_the_point_cloud() -> None:
    renderer = DepthRenderer(camera("16UC1"), [WALL])
    depth = renderer.render(0.0, 0.0, 0.5, 0.0)
    millimetres = np.frombuffer(renderer.image_bytes(depth), dtype="<u2").reshape(48, 64)
    centre = 24
    assert millimetres[centre, 32] == 2900
    assert (millimetres[depth == np.inf] == 0).all()  # REP 118: 0 is "no reading" for uint16
    cloud = np.frombuffer(renderer.cloud_bytes(depth), dtype="<f4").reshape(48, 64, 3)
    x, y, z = cloud[centre, 32]
    assert z == pytest.approx(2.9, abs=1e-5)
    assert x == pytest.approx(renderer.a[32] * 2.9, abs=1e-5)
    assert y == pytest.approx(renderer.b[centre] * 2.9, abs=1e-5)
    assert np.isnan(cloud[depth == np.inf]).all()  # outside [min_depth, max_depth]


def test_turning_away_leaves_nothing_in_view() -> None:
    renderer = DepthRenderer(camera(), [WALL])
    depth = renderer.render(0.0, 0.0, 0.3, math.pi)
    above_horizon = renderer.b < 0
    assert (depth[above_horizon, :] == np.inf).all()


def test_jtbot_depth_camera_is_read_from_its_urdf() -> None:
    import xml.etree.ElementTree as ET

    urdf = ET.tostring(process(JTBOT_XACRO), encoding="unicode")
    spec = describe_model(parse_urdf(urdf), "jtbot")
    assert not [w for w in spec.warnings if "depth" in w], spec.warnings
    (cam,) = spec.cameras
    assert (cam.width, cam.height, cam.update_rate, cam.encoding) == (640, 480, 30.0, "32FC1")
    assert (cam.depth_topic, cam.depth_info_topic, cam.points_topic) == (
        "/depth_camera/depth/image_raw",
        "/depth_camera/depth/camera_info",
        "/depth_camera/points",
    )
    assert cam.frame_id == "camera_depth_frame"
    assert (cam.min_depth, cam.max_depth, cam.near, cam.far) == (0.5, 3.0, 0.05, 3.0)
    assert cam.mount.x > 0  # on the front face of the chassis


# The test robot with a depth camera on the front of its base, 0.1 ahead of the base origin and
# 0.12 up, looking forward: the wall face is WALL_FACE - 0.1 away from it.
CAMERA_URDF = URDF.replace(
    "</robot>",
    """
  <link name="camera_link"/>
  <joint name="camera_joint" type="fixed"><parent link="base_link"/><child link="camera_link"/>
    <origin xyz="0.1 0 0.12"/></joint>
  <gazebo reference="camera_link">
    <sensor name="cam" type="depth">
      <update_rate>10</update_rate>
      <camera><horizontal_fov>1.0</horizontal_fov>
        <image><width>80</width><height>60</height><format>R8G8B8</format></image>
        <clip><near>0.05</near><far>8</far></clip></camera>
      <plugin name="cam_controller" filename="libgazebo_ros_camera.so">
        <frame_name>camera_optical</frame_name>
      </plugin>
    </sensor>
  </gazebo>
</robot>""",
)

IMAGE_PROBE = r"""
import json, sys, time
import array
import rclpy
from sensor_msgs.msg import CameraInfo, Image
rclpy.init()
node = rclpy.create_node("depth_probe")
got = {}
node.create_subscription(Image, "/cam/depth/image_raw", lambda m: got.setdefault("image", m), 10)
node.create_subscription(CameraInfo, "/cam/depth/camera_info", lambda m: got.setdefault("info", m), 10)
deadline = time.monotonic() + 30
while len(got) < 2 and time.monotonic() < deadline:
    rclpy.spin_once(node, timeout_sec=0.05)
if len(got) < 2:
    print(json.dumps({"error": "timeout", "have": sorted(got)}))
    sys.exit(3)
image, info = got["image"], got["info"]
values = array.array("f", bytes(image.data))
print(json.dumps({
    "size": [image.width, image.height], "encoding": image.encoding, "frame": image.header.frame_id,
    "centre": values[(image.height // 2) * image.width + image.width // 2],
    "k": list(info.k), "info_frame": info.header.frame_id,
}))
"""


@requires_rclpy
def test_depth_image_of_the_wall_through_the_simulator(
    tmp_path: Path, ros_env: dict[str, str], world_file: Path, sim_factory: Callable[..., Sim]
) -> None:
    urdf = tmp_path / "camerabot.urdf"
    urdf.write_text(CAMERA_URDF)
    sim = sim_factory(str(world_file), "--ros-args", "-p", "use_sim_time:=true")
    done = spawn(["spawn_entity.py", "-entity", "camerabot", "-file", str(urdf)], ros_env)
    assert done.returncode == 0, done.stderr + sim.stderr()
    assert "depth camera /cam/depth/image_raw 80x60 32FC1 @10 Hz" in sim.stdout()
    probe = subprocess.run(
        [sys.executable, "-c", IMAGE_PROBE],
        env=ros_env,
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert probe.returncode == 0, probe.stdout + probe.stderr
    seen = json.loads(probe.stdout.strip().splitlines()[-1])
    assert seen["size"] == [80, 60] and seen["encoding"] == "32FC1"
    assert seen["frame"] == seen["info_frame"] == "camera_optical"
    assert seen["centre"] == pytest.approx(WALL_FACE - 0.1, abs=1e-4)
    focal = 80 / (2 * math.tan(0.5))
    assert seen["k"] == pytest.approx([focal, 0, 40.5, 0, focal, 30.5, 0, 0, 1])
    assert "not simulated" not in sim.stderr()
