"""The evidence of a failed `mlaunch test` run: verdict, plan, processes, logs, a backtrace of a
core dump, and the last seconds of the named topics as MCAP (issue 32 item 3)."""

from __future__ import annotations

import importlib.util
import json
import re
import shutil
import sys
from pathlib import Path

import pytest
from procutil import clean_env, demo_package, run_mlaunch

from mlaunch.ros import msgdef

CRASHES = """
import sys
from launch import LaunchDescription
from launch.actions import ExecuteProcess

CODE = "import sys, time; print('starting up', flush=True); time.sleep(%(wait)s); sys.exit(4)"

def generate_launch_description():
    return LaunchDescription([
        ExecuteProcess(cmd=[sys.executable, "-c", CODE], name="worker",
                       additional_env={"WORKER_MODE": "fast"}),
    ])
"""

ABORTS = """
import sys
from launch import LaunchDescription
from launch.actions import ExecuteProcess

CODE = (
    "import os, resource, time; resource.setrlimit(resource.RLIMIT_CORE, (-1, -1));"
    " print('about to abort', flush=True); time.sleep(1); os.abort()"
)

def generate_launch_description():
    return LaunchDescription([
        ExecuteProcess(cmd=[sys.executable, "-c", CODE], name="aborts", cwd=%(cwd)r),
    ])
"""

# Publishes std_msgs/String on /chatter at 20 Hz.
CHATTER = """
import rclpy
from rclpy.node import Node
from std_msgs.msg import String

rclpy.init()
node = Node("chatter")
pub = node.create_publisher(String, "/chatter", 10)
count = [0]

def tick():
    count[0] += 1
    pub.publish(String(data=f"hello {count[0]}"))

node.create_timer(0.05, tick)
try:
    rclpy.spin(node)
except BaseException:
    pass
"""


def _evidence(out: str) -> Path:
    match = re.search(r"evidence: (\S+) \((\d+) files, (\d+) KB\)", out)
    assert match, out
    return Path(match[1])


def test_a_failed_run_leaves_its_evidence_in_its_log_folder(tmp_path: Path) -> None:
    path = tmp_path / "crash.launch.py"
    path.write_text(CRASHES % {"wait": 1})
    logs = tmp_path / "logs"
    done = run_mlaunch("test", str(path), env=clean_env(ROS_LOG_DIR=str(logs)))
    assert done.returncode == 1, done.stdout + done.stderr
    folder = _evidence(done.stdout)
    assert folder.parent.parent == logs and folder.name == "artifacts"
    verdict = json.loads((folder / "verdict.json").read_text())
    assert verdict["passed"] is False
    assert any("exited with status 4" in c["seen"] for c in verdict["checks"])
    plan = json.loads((folder / "plan.json").read_text())
    assert plan["launch_file"].endswith("crash.launch.py") and plan["steps"]
    (worker,) = json.loads((folder / "processes.json").read_text())
    assert worker["label"] == "worker-1" and worker["argv"][0] == sys.executable
    assert worker["environment"]["WORKER_MODE"] == "fast"
    assert worker["ended"] == "exited with status 4" and worker["last_output"] == ["starting up"]
    assert (folder / "logs" / "worker-1.log").read_text().count("starting up") == 1
    assert (folder / "logs" / "launch.log").exists()


def test_a_passing_run_writes_evidence_only_when_asked(tmp_path: Path) -> None:
    path = tmp_path / "steady.launch.py"
    path.write_text(CRASHES % {"wait": 60})
    env = clean_env(ROS_LOG_DIR=str(tmp_path / "logs"))
    done = run_mlaunch("test", str(path), "--hold", "0", env=env)
    assert done.returncode == 0 and "evidence:" not in done.stdout, done.stdout
    assert not list((tmp_path / "logs").glob("*/artifacts"))
    wanted = tmp_path / "evidence"
    done = run_mlaunch("test", str(path), "--hold", "0", "--artifacts", str(wanted), env=env)
    assert done.returncode == 0, done.stdout + done.stderr
    assert _evidence(done.stdout) == wanted
    assert json.loads((wanted / "verdict.json").read_text())["passed"] is True


def test_the_parameters_a_node_was_given_are_kept(tmp_path: Path) -> None:
    prefix = demo_package(tmp_path)
    path = tmp_path / "p.launch.py"
    path.write_text(
        "from launch import LaunchDescription\nfrom launch_ros.actions import Node\n"
        "def generate_launch_description():\n"
        "    return LaunchDescription([Node(package='demo', executable='talker',"
        " parameters=[{'speed': 3, 'mode': 'fast'}])])\n"
    )
    evidence = tmp_path / "e"
    env = clean_env(AMENT_PREFIX_PATH=prefix)
    done = run_mlaunch("test", str(path), "--hold", "0", "--artifacts", str(evidence), env=env)
    assert "evidence:" in done.stdout, done.stdout + done.stderr
    (talker,) = json.loads((evidence / "processes.json").read_text())
    (params,) = [p for p in talker["parameters"] if "file" in p]
    assert "speed: 3" in params["content"] and "mode: fast" in params["content"]


@pytest.mark.skipif(shutil.which("gdb") is None, reason="gdb is not installed")
def test_a_core_dump_gets_a_backtrace(tmp_path: Path) -> None:
    if Path("/proc/sys/kernel/core_pattern").read_text().startswith("|"):
        pytest.skip("core dumps are piped to a handler here (kernel.core_pattern)")
    path = tmp_path / "aborts.launch.py"
    path.write_text(ABORTS % {"cwd": str(tmp_path)})
    evidence = tmp_path / "e"
    done = run_mlaunch(
        "test", str(path), "--artifacts", str(evidence), env=clean_env(), timeout=180
    )
    assert done.returncode == 1, done.stdout + done.stderr
    (aborted,) = json.loads((evidence / "processes.json").read_text())
    assert aborted["core_dumped"] is True, aborted
    assert aborted["backtrace"] == "backtraces/aborts-1.txt", aborted["backtrace"]
    text = (evidence / "backtraces" / "aborts-1.txt").read_text()
    assert "#0" in text, text


def test_without_a_verdict_the_writer_leaves_it_out_and_runs_no_gdb(tmp_path: Path) -> None:
    """The launch panel's bundle of a live run: no verdict.json, no gdb over a core."""
    from mlaunch.engine.process import Process
    from mlaunch.plan.steps import ProcessSpec
    from mlaunch.smoke import artifacts

    spec = ProcessSpec("dumped-1", ("/bin/false",), {"A": "1"}, {})
    dumped = Process(spec, 0)
    dumped.pid, dumped.returncode, dumped.core_dumped = 4321, -6, True
    logs = tmp_path / "logs"
    logs.mkdir()
    (logs / "dumped-1.log").write_text("last words\n")
    folder = tmp_path / "bundle"
    bundle = artifacts.write(
        str(folder),
        verdict=None,
        plan_text="{}\n",
        processes=[dumped],
        rings={"dumped-1": ["last words"]},
        log_dir=str(logs),
        backtraces=False,
    )
    assert sorted(bundle.files) == ["logs/dumped-1.log", "plan.json", "processes.json"]
    (record,) = json.loads((folder / "processes.json").read_text())
    assert record["core_dumped"] and record["backtrace"].startswith("not taken here")
    assert not (folder / "backtraces").exists()


def test_a_packed_bundle_stops_at_its_size_and_names_what_it_left_out(tmp_path: Path) -> None:
    import io
    import tarfile

    from mlaunch.smoke import artifacts

    (tmp_path / "logs").mkdir()
    (tmp_path / "plan.json").write_text("{}")
    (tmp_path / "logs" / "big.log").write_bytes(b"x" * 5000)
    (tmp_path / "logs" / "small.log").write_bytes(b"y" * 10)
    (tmp_path / "logs" / "elsewhere.log").symlink_to("/etc/hostname")
    data, left = artifacts.pack(str(tmp_path), "b", limit=1000)
    assert left == ["logs/big.log (5000 bytes)"]
    with tarfile.open(fileobj=io.BytesIO(data), mode="r:gz") as tar:
        names = sorted(tar.getnames())
        note = tar.extractfile("b/LEFT_OUT.txt")
        assert note is not None and b"logs/big.log" in note.read()
    assert names == ["b/LEFT_OUT.txt", "b/logs/small.log", "b/plan.json"]


def test_a_message_definition_is_the_ros2msg_schema_a_reader_decodes() -> None:
    mcap_ros2 = pytest.importorskip("mcap_ros2._dynamic")
    pytest.importorskip("geometry_msgs")
    text = msgdef.definition("geometry_msgs/msg/PoseStamped")
    assert text.startswith("# A Pose with reference coordinate frame and timestamp")
    assert "\nMSG: std_msgs/Header\n" in text and "\nMSG: geometry_msgs/Quaternion\n" in text
    decoders = mcap_ros2.generate_dynamic("geometry_msgs/msg/PoseStamped", text)
    assert "geometry_msgs/Pose" in decoders
    assert msgdef.used_types("int32 X=3\nstring a\nfoo/Bar[] b  # c\nBaz<=3 q\n") == [
        "foo/Bar",
        "Baz",
    ]
    with pytest.raises(msgdef.MessageDefinitionError, match="no definition of nope/msg/Nope"):
        msgdef.definition("nope/msg/Nope")


@pytest.mark.skipif(
    importlib.util.find_spec("rclpy") is None or importlib.util.find_spec("mcap_ros2") is None,
    reason="needs rclpy and mcap-ros2-support (./scripts/setup)",
)
def test_the_last_seconds_of_the_named_topics_are_an_mcap_file(
    tmp_path: Path, ros_env: dict[str, str]
) -> None:
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory

    script = tmp_path / "chatter.py"
    script.write_text(CHATTER)
    path = tmp_path / "chatter.launch.yaml"
    path.write_text(f'launch:\n- executable: {{cmd: "{sys.executable} {script}", name: chatter}}\n')
    evidence = tmp_path / "e"
    args = ["--expect-topic", "/chatter", "--record-seconds", "2", "--hold", "4"]
    done = run_mlaunch(
        "test", str(path), *args, "--artifacts", str(evidence), env=clean_env(), timeout=120
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert re.search(r"recording\.mcap: \d+ messages on 1 topics", done.stdout), done.stdout
    with open(evidence / "recording.mcap", "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        seen = [
            (schema.name if schema else "", channel.topic, message.log_time, decoded.data)
            for schema, channel, message, decoded in reader.iter_decoded_messages()
        ]
    assert seen and {(s[0], s[1]) for s in seen} == {("std_msgs/msg/String", "/chatter")}
    assert all(s[3].startswith("hello ") for s in seen)
    span = (seen[-1][2] - seen[0][2]) / 1e9
    assert span <= 2.1, span  # a ring of the last 2 s, not the whole run
