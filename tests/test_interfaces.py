"""The ROS interface packages scripts/setup builds from interfaces/ (tf2_msgs, composition_interfaces).

The wire checks need the wheels installed (scripts/setup does it where a compiler is present) and
skip with the reason otherwise; the build script's cache key and its refusal without a compiler
are checked without building anything.
"""

from __future__ import annotations

import importlib.util
import os
import shutil
import subprocess
import sys
import textwrap
import zipfile
from pathlib import Path
from types import ModuleType

import pytest
from conftest import HAVE_RCLPY, REPO

INTERFACES = REPO / "interfaces"
HAVE_TF2_MSGS = HAVE_RCLPY and importlib.util.find_spec("tf2_msgs") is not None
requires_tf2_msgs = pytest.mark.skipif(
    not HAVE_TF2_MSGS,
    reason="tf2_msgs is not installed: ./scripts/setup builds it (needs cmake, gcc)",
)

# Type hashes of ROS 2 Jazzy (REP-2011 RIHS01), as a real Jazzy installation reports them: the
# copper-rs pull request #1371 lists tf2_msgs/msg/TFMessage's "Jazzy RIHS01 hash" (checked there
# against its all_rihs.md), and `ros2 topic info -v /tf` on Jazzy machines as well as rosbag2
# metadata.yaml files recorded on Jazzy (`type_description_hash:`) show the same value. The
# TF2Error one is from the same golden-hash list of a Jazzy-compatible CDR library.
JAZZY_HASHES = {
    "tf2_msgs/msg/TFMessage": (
        "RIHS01_e369d0f05a23ae52508854b66f6aa0437f3449d652e8cbf22d5abe85d020f087"
    ),
    "tf2_msgs/msg/TF2Error": (
        "RIHS01_db2485e7d6a0ec75bf087e058ee45df682acc3a621ca7780503d10aac141809a"
    ),
}


def _load_build_script(folder: Path) -> ModuleType:
    spec = importlib.util.spec_from_file_location("interfaces_build", folder / "build.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_cache_key_follows_the_definitions_and_the_tool_chain(tmp_path: Path) -> None:
    copy = tmp_path / "interfaces"
    shutil.copytree(INTERFACES, copy, ignore=shutil.ignore_patterns("__pycache__"))
    build = _load_build_script(copy)
    first = build.build_key()
    assert build.build_key() == first, "the key must not depend on when it is computed"
    assert first == _load_build_script(INTERFACES).build_key(), "a copy has the same key"

    message = copy / "tf2_msgs" / "msg" / "TFMessage.msg"
    message.write_text(message.read_text() + "string extra\n")
    assert build.build_key() != first

    message.write_text(message.read_text().replace("string extra\n", ""))
    assert build.build_key() == first
    toolchain_before = build.toolchain_key()
    pins = copy / "toolchain.txt"
    pins.write_text(pins.read_text().replace("empy==4.2.1", "empy==4.2"))
    assert build.build_key() != first
    assert build.toolchain_key() != toolchain_before


def test_no_compiler_is_one_clear_line_and_exit_2(tmp_path: Path) -> None:
    env = dict(os.environ, MLAUNCH_INTERFACES_CACHE=str(tmp_path), CC="/nonexistent/cc")
    done = subprocess.run(
        [sys.executable, str(INTERFACES / "build.py")],
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert done.returncode == 2, done.stderr
    assert done.stdout == ""
    assert done.stderr.strip().splitlines() == [
        "interfaces/build.py: cannot build the ROS interface packages: missing /nonexistent/cc "
        "(on Debian: apt-get install cmake gcc g++ python3-dev)"
    ]
    assert not list(tmp_path.iterdir()), "nothing is cached or installed when the build cannot run"


def test_wheel_layout_matches_the_ros_wheels(tmp_path: Path) -> None:
    """site-packages content at the wheel's root, libraries and share/ as prefix data."""
    build = _load_build_script(INTERFACES)
    prefix = tmp_path / "prefix"
    site = prefix / build.SITE / "tf2_msgs"
    (site / "msg").mkdir(parents=True)
    (site / "msg" / "__init__.py").write_text("")
    (site / "__pycache__").mkdir()
    (site / "__pycache__" / "x.pyc").write_text("")
    (prefix / "lib").mkdir(exist_ok=True)
    (prefix / "lib" / "libtf2_msgs__rosidl_generator_c.so").write_bytes(b"\x7fELF")
    index = prefix / "share" / "ament_index" / "resource_index" / "packages"
    index.mkdir(parents=True)
    (index / "tf2_msgs").write_text("")
    wheel = build.pack_wheel("tf2_msgs", prefix, tmp_path)
    version = build.package_version("tf2_msgs")
    with zipfile.ZipFile(wheel) as archive:
        names = set(archive.namelist())
        record = archive.read(f"mlaunch_tf2_msgs-{version}.dist-info/RECORD").decode()
    data = f"mlaunch_tf2_msgs-{version}.data/data/"
    assert names == {
        "tf2_msgs/msg/__init__.py",
        data + "lib/libtf2_msgs__rosidl_generator_c.so",
        data + "share/ament_index/resource_index/packages/tf2_msgs",
        *(f"mlaunch_tf2_msgs-{version}.dist-info/{n}" for n in ("METADATA", "WHEEL", "RECORD")),
        f"mlaunch_tf2_msgs-{version}.dist-info/top_level.txt",
    }
    assert all(name in record for name in names)


HASH_PROBE = textwrap.dedent(
    """
    import sys, time
    import rclpy
    from rclpy.node import Node
    from tf2_msgs.msg import TF2Error, TFMessage

    rclpy.init()
    node = Node("hash_probe")
    for topic, kind in (("/hash_probe_tf", TFMessage), ("/hash_probe_error", TF2Error)):
        node.create_publisher(kind, topic, 1)
    deadline = time.monotonic() + 20
    while time.monotonic() < deadline:
        infos = [node.get_publishers_info_by_topic(t) for t in ("/hash_probe_tf", "/hash_probe_error")]
        if all(infos):
            for info in infos:
                print(info[0].topic_type, str(info[0].topic_type_hash))
            sys.exit(0)
        rclpy.spin_once(node, timeout_sec=0.05)
    sys.exit(3)
    """
)


@requires_tf2_msgs
@pytest.mark.timeout(60)
def test_built_type_hashes_equal_jazzy(ros_env: dict[str, str]) -> None:
    """What our publishers announce on the wire is what a real Jazzy subscriber expects."""
    done = subprocess.run(
        [sys.executable, "-c", HASH_PROBE],
        env=ros_env,
        capture_output=True,
        text=True,
        timeout=45,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    seen = dict(line.split() for line in done.stdout.splitlines())
    assert seen == JAZZY_HASHES


@requires_tf2_msgs
def test_composition_interfaces_has_launch_ros_request_fields() -> None:
    from composition_interfaces.srv import ListNodes, LoadNode, UnloadNode

    request = LoadNode.Request()
    assert list(request.get_fields_and_field_types()) == [
        "package_name",
        "plugin_name",
        "node_name",
        "node_namespace",
        "log_level",
        "remap_rules",
        "parameters",
        "extra_arguments",
    ]
    assert list(LoadNode.Response.get_fields_and_field_types()) == [
        "success",
        "error_message",
        "full_node_name",
        "unique_id",
    ]
    assert list(UnloadNode.Request.get_fields_and_field_types()) == ["unique_id"]
    assert list(ListNodes.Response.get_fields_and_field_types()) == [
        "full_node_names",
        "unique_ids",
    ]
