"""demo_nodes_py (ROS 2's pure Python demo package) under ``scripts/setup --real-nodes``: how
``scripts/real_nodes/python_packages.py`` packs a package (on a small one made here), and mlaunch
on the real one where setup installed it (its programs are ``lib/demo_nodes_py/NAME`` in the
venv's ament prefix, run by the venv's Python).
"""

from __future__ import annotations

import io
import os
import subprocess
import sys
import tarfile
import zipfile
from pathlib import Path

import pytest
from conftest import VENV_PREFIX, requires_rclpy
from procutil import REPO, clean_env, mlaunch

PREFIX = Path(VENV_PREFIX)
TALKER_QOS = PREFIX / "lib" / "demo_nodes_py" / "talker_qos"
LIFECYCLE_TALKER = PREFIX / "lib" / "lifecycle_py" / "lifecycle_talker"
requires_lifecycle_py = pytest.mark.skipif(
    not os.access(LIFECYCLE_TALKER, os.X_OK),
    reason=f"lifecycle_py is not installed ({LIFECYCLE_TALKER} is missing): run scripts/setup"
    " --real-nodes [DIR] with a demos archive that has lifecycle_py (CI does)",
)
requires_demo_nodes_py = pytest.mark.skipif(
    not os.access(TALKER_QOS, os.X_OK),
    reason=f"demo_nodes_py is not installed ({TALKER_QOS} is missing): run scripts/setup"
    " --real-nodes [DIR] with a demos archive that has demo_nodes_py (CI does)",
)
PACKER = REPO / "scripts" / "real_nodes" / "python_packages.py"
SETUP_PY = """
from setuptools import find_packages, setup
package_name = 'demo_nodes_py'
setup(
    name=package_name,
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
    ],
    entry_points={'console_scripts': ['hello = demo_nodes_py.topics.hello:main']},
)
"""
HELLO = """import sys
def main():
    print('hello', sys.argv[1:], sys.prefix)
    return 3
"""

LAUNCH = """
from launch import LaunchDescription
from launch_ros.actions import Node


def generate_launch_description():
    return LaunchDescription([
        Node(
            package='demo_nodes_py', executable='talker_qos', name='qos_talker',
            arguments=['--reliable', '-n', '3'], remappings=[('chatter', 'demo_chatter')],
            output='screen',
        ),
    ])
"""


def make_sources(root: Path) -> Path:
    """A sources folder whose one archive (``pydemos``) has a small demo_nodes_py."""
    files = {
        "setup.py": SETUP_PY,
        "package.xml": "<package format='3'><name>demo_nodes_py</name></package>",
        "resource/demo_nodes_py": "",
        "demo_nodes_py/__init__.py": "",
        "demo_nodes_py/topics/__init__.py": "",
        "demo_nodes_py/topics/hello.py": HELLO,
        "test/test_nothing.py": "",
    }
    root.mkdir()
    with tarfile.open(root / "pydemos.tar.gz", "w:gz") as archive:
        for name, text in files.items():
            info = tarfile.TarInfo(f"pydemos/demo_nodes_py/{name}")
            info.size = len(text.encode())
            archive.addfile(info, io.BytesIO(text.encode()))
    (root / "MANIFEST.tsv").write_text(
        "archive\trepo\tref\tcommit\tpaths\tsha256\n"
        "pydemos.tar.gz\tros2/demos\tjazzy\tabc123\tdemo_nodes_py LICENSE\t-\n"
    )
    return root


def pack(sources: Path, cache: Path, *extra: str) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "MLAUNCH_REAL_NODES_CACHE": str(cache)}
    return subprocess.run(
        [sys.executable, str(PACKER), str(sources), *extra],
        capture_output=True, text=True, env=env, timeout=60,
    )  # fmt: skip


def test_the_packer_lays_the_package_out_as_colcon_and_caches_it(tmp_path: Path) -> None:
    sources = make_sources(tmp_path / "src")
    done = pack(sources, tmp_path / "cache")
    assert done.returncode == 0, done.stderr
    folder = Path(done.stdout.strip())
    assert folder.parent == tmp_path / "cache" and (folder / ".complete").is_file()
    assert pack(sources, tmp_path / "cache", "--key").stdout.strip() in folder.name
    (wheel,) = folder.glob("*.whl")
    data = "mlaunch_real_nodes_py-0.1.0.data/data/"
    with zipfile.ZipFile(wheel) as archive:
        names = set(archive.namelist())
        mode = archive.getinfo(data + "lib/demo_nodes_py/hello").external_attr >> 16
        archive.extractall(tmp_path / "wheel")
    assert {
        data + "share/ament_index/resource_index/packages/demo_nodes_py",
        data + "share/demo_nodes_py/package.xml",
        "demo_nodes_py/topics/hello.py",
    } <= names
    assert not [name for name in names if "test_nothing" in name]
    assert mode & 0o755 == 0o755
    # Installed: the program runs on the Python of the prefix it is in (here a link to this one).
    prefix = tmp_path / "wheel" / data.rstrip("/")
    (prefix / "lib" / "demo_nodes_py" / "hello").chmod(mode & 0o777)  # as pip sets it
    (prefix / "bin").mkdir()
    (prefix / "bin" / "python3").symlink_to(sys.executable)
    env = {**os.environ, "PYTHONPATH": str(tmp_path / "wheel")}
    ran = subprocess.run(
        [str(prefix / "lib" / "demo_nodes_py" / "hello"), "a b", "c"],
        capture_output=True, text=True, env=env, timeout=30,
    )  # fmt: skip
    assert ran.returncode == 3, ran.stderr
    assert ran.stdout.startswith("hello ['a b', 'c'] "), ran.stdout
    again = pack(sources, tmp_path / "cache")
    assert (
        again.stdout == done.stdout
        and wheel.stat().st_mtime_ns == next(folder.glob("*.whl")).stat().st_mtime_ns
    )


def test_the_packer_says_when_no_archive_has_the_package(tmp_path: Path) -> None:
    sources = make_sources(tmp_path / "src")
    manifest = sources / "MANIFEST.tsv"
    manifest.write_text(manifest.read_text().replace("demo_nodes_py LICENSE", "LICENSE"))
    done = pack(sources, tmp_path / "cache")
    assert done.returncode == 2 and done.stdout == ""
    assert f"no archive of {sources} has demo_nodes_py or lifecycle_py" in done.stderr, done.stderr


def test_the_packer_packs_lifecycle_py_beside_demo_nodes_py(tmp_path: Path) -> None:
    """Both packages of one archive go into the one wheel; one an archive lacks is said."""
    sources = make_sources(tmp_path / "src")
    done = pack(sources, tmp_path / "cache")
    assert done.returncode == 0 and "warning: no archive of" in done.stderr
    assert "has lifecycle_py" in done.stderr, done.stderr
    files = {
        "setup.py": SETUP_PY.replace("'demo_nodes_py'", "'lifecycle_py'").replace(
            "hello = demo_nodes_py.topics.hello:main", "lifecycle_talker = lifecycle_py.talker:main"
        ),
        "package.xml": "<package format='3'><name>lifecycle_py</name></package>",
        "resource/lifecycle_py": "",
        "lifecycle_py/__init__.py": "",
        "lifecycle_py/talker.py": "def main():\n    return 0\n",
    }
    with tarfile.open(sources / "pylife.tar.gz", "w:gz") as archive:
        for name, text in files.items():
            info = tarfile.TarInfo(f"pylife/lifecycle_py/{name}")
            info.size = len(text.encode())
            archive.addfile(info, io.BytesIO(text.encode()))
    with (sources / "MANIFEST.tsv").open("a") as manifest:
        manifest.write("pylife.tar.gz\tros2/demos\tjazzy\tdef456\tlifecycle_py\t-\n")
    done = pack(sources, tmp_path / "cache")
    assert done.returncode == 0 and "warning" not in done.stderr, done.stderr
    (wheel,) = Path(done.stdout.strip()).glob("*.whl")
    data = "mlaunch_real_nodes_py-0.1.0.data/data/"
    with zipfile.ZipFile(wheel) as archive:
        names = set(archive.namelist())
        metadata = archive.read("mlaunch_real_nodes_py-0.1.0.dist-info/METADATA").decode()
    assert {data + "lib/demo_nodes_py/hello", data + "lib/lifecycle_py/lifecycle_talker"} <= names
    assert "lifecycle_py/talker.py" in names
    assert "Source: ros2/demos abc123" in metadata and "Source: ros2/demos def456" in metadata


@requires_rclpy
@requires_demo_nodes_py
@pytest.mark.timeout(120)
def test_talker_qos_runs_under_mlaunch(ros_env: dict[str, str], tmp_path: Path) -> None:
    """The node is found in the venv's prefix (not a stand-in), gets its own arguments and the
    ROS ones (its name), publishes, and its exit after 3 cycles ends the launch with 0."""
    launch = tmp_path / "talker_qos.launch.py"
    launch.write_text(LAUNCH)
    env = clean_env(**ros_env)
    env["ROS_LOG_DIR"] = str(tmp_path / "log")
    others = [e for e in env.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if e]
    env["AMENT_PREFIX_PATH"] = os.pathsep.join([str(PREFIX), *others])
    shown = subprocess.run(
        mlaunch(str(launch), "--print"), capture_output=True, text=True, env=env, timeout=60
    )
    assert shown.returncode == 0, shown.stderr
    assert str(TALKER_QOS) in shown.stdout, shown.stdout
    done = subprocess.run(
        mlaunch(str(launch)), capture_output=True, text=True, env=env, timeout=90, cwd=tmp_path
    )
    out = done.stdout + done.stderr
    assert done.returncode == 0, out[-3000:]
    assert "[qos_talker]: Reliable talker" in out, out[-3000:]
    assert '[qos_talker]: Publishing: "Hello World: 0"' in out, out[-3000:]
    assert "not installed" not in out, out[-3000:]


LIFECYCLE_LAUNCH = """
from launch import LaunchDescription
from launch_ros.actions import LifecycleNode


def generate_launch_description():
    return LaunchDescription([
        LifecycleNode(
            package='lifecycle_py', executable='lifecycle_talker', name='lc_talker',
            namespace='', autostart=True, output='screen',
        ),
    ])
"""


@requires_rclpy
@requires_lifecycle_py
@pytest.mark.timeout(150)
def test_the_real_lifecycle_talker_autostarts_to_active(
    ros_env: dict[str, str], tmp_path: Path
) -> None:
    """lifecycle_py's own talker (not a stand-in) under a LifecycleNode with autostart: mlaunch
    configures and activates it, --expect-lifecycle sees it active, it publishes once active."""
    launch = tmp_path / "lifecycle_talker.launch.py"
    launch.write_text(LIFECYCLE_LAUNCH)
    env = clean_env(**ros_env)
    env["ROS_LOG_DIR"] = str(tmp_path / "log")
    others = [e for e in env.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if e]
    env["AMENT_PREFIX_PATH"] = os.pathsep.join([str(PREFIX), *others])
    done = subprocess.run(
        mlaunch("test", str(launch), "--expect-lifecycle", "/lc_talker", "--hold", "2"),
        capture_output=True, text=True, env=env, timeout=140, cwd=tmp_path,
    )  # fmt: skip
    out = done.stdout + done.stderr
    assert done.returncode == 0, out[-3000:]
    assert "not installed" not in out, out[-3000:]  # the real program, no stand-in
    assert "[lc_talker]: on_configure() is called." in out, out[-3000:]
    assert "lifecycle node /lc_talker is active" in out and "state 'active'" in out, out[-3000:]
    assert "Lifecycle publisher is active. Publishing: [Lifecycle HelloWorld #0]" in out
