"""The expectations users write by hand today: a TF link, a parameter value, an action server,
no forbidden output (--forbid-output, --no-errors), from the command line or the launch file
(issue 32 item 4)."""

from __future__ import annotations

import importlib.util
import json
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from procutil import clean_env, run_mlaunch

from mlaunch.plan.errors import UsageError
from mlaunch.smoke.expectations import ERROR_LINES, parse_spec
from mlaunch.smoke.settings import parse_settings

# A node offering what the graph checks look at: odom -> base_link on /tf_static, parameter
# rate = 5, and the send_goal service an action server /nav offers.
PROBE = """
import rclpy
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile
from geometry_msgs.msg import TransformStamped
from lifecycle_msgs.srv import GetState
from tf2_msgs.msg import TFMessage

rclpy.init()
node = Node("probe")
node.declare_parameter("rate", 5)
latched = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
pub = node.create_publisher(TFMessage, "/tf_static", latched)
t = TransformStamped()
t.header.frame_id, t.child_frame_id = "odom", "base_link"
pub.publish(TFMessage(transforms=[t]))
node.create_service(GetState, "/nav/_action/send_goal", lambda req, res: res)
try:
    rclpy.spin(node)
except BaseException:
    pass
"""

SAYS = """
import sys
from launch import LaunchDescription
from launch.actions import ExecuteProcess, SetLaunchConfiguration

CODE = "import time; print(%(line)r, flush=True); time.sleep(60)"

def generate_launch_description():
    return LaunchDescription([
        %(let)s
        ExecuteProcess(cmd=[sys.executable, "-c", CODE], name="talker"),
    ])
"""


def _row(out: str, text: str) -> str:
    table = out[out.rindex("\nmlaunch test ") :]
    return next(line.strip() for line in table.splitlines() if text in line)


def test_the_new_kinds_parse_and_bad_ones_say_what_is_valid() -> None:
    tf = parse_spec("tf /odom:base_link within 5", "t")
    assert (tf.kind, tf.target, tf.within) == ("tf", "odom:base_link", 5.0)
    param = parse_spec("param robot_state_publisher:publish_frequency=20.0", "t")
    assert (param.target, param.value) == ("/robot_state_publisher:publish_frequency", "20.0")
    assert param.describe() == "parameter publish_frequency of /robot_state_publisher is 20.0"
    assert parse_spec("action navigate_to_pose", "t").target == "/navigate_to_pose"
    forbid = parse_spec("forbid Traceback", "t")
    assert (
        forbid.status == "met" and forbid.describe() == "no line of any process matches /Traceback/"
    )
    for text, message in [
        ("tf odom", "PARENT:CHILD"),
        ("param /n:x", "/NODE:NAME=VALUE"),
        ("param x=1", "/NODE:NAME=VALUE"),
    ]:
        with pytest.raises(UsageError, match=message):
            parse_spec(text, "t")
    settings = parse_settings(["--no-errors", "--expect-tf", "map:odom"])
    assert [e.kind for e in settings.expectations] == ["tf", "forbid"]
    assert settings.expectations[1].target == ERROR_LINES


@pytest.mark.parametrize(
    ("line", "args", "failed"),
    [
        ("[ERROR] [talker]: boom", ["--no-errors"], "no ERROR or FATAL line"),
        ("all fine", ["--no-errors"], None),
        ("[ERROR] [talker]: boom", [], None),  # off by default
        ("warning: disk full", ["--forbid-output", "talker:disk (full|gone)"], "no line of talker"),
        ("warning: disk full", ["--forbid-output", "other:disk"], None),
    ],
)
def test_forbidden_output_fails_the_test(
    tmp_path: Path, line: str, args: list[str], failed: str | None
) -> None:
    path = tmp_path / "says.launch.py"
    path.write_text(SAYS % {"line": line, "let": ""})
    done = run_mlaunch("test", str(path), "--hold", "1", *args, env=clean_env())
    out = done.stdout + done.stderr
    if failed is None:
        assert done.returncode == 0, out
        return
    assert done.returncode == 1, out
    row = _row(done.stdout, failed)
    assert row.startswith("FAIL") and f"talker-1: {line}" in row, out


def test_a_forbidden_output_declared_in_the_launch_file(tmp_path: Path) -> None:
    path = tmp_path / "says.launch.py"
    let = 'SetLaunchConfiguration("mlaunch_expect_clean", "forbid Traceback"),'
    path.write_text(SAYS % {"line": "Traceback (most recent call last):", "let": let})
    done = run_mlaunch("test", str(path), "--hold", "1", env=clean_env())
    assert done.returncode == 1, done.stdout + done.stderr
    assert _row(done.stdout, "matches /Traceback/").startswith("FAIL")


@pytest.mark.skipif(
    importlib.util.find_spec("rclpy") is None or importlib.util.find_spec("tf2_msgs") is None,
    reason="needs rclpy and tf2_msgs (./scripts/setup)",
)
def test_tf_param_and_action_checks_against_a_running_node(
    tmp_path: Path, ros_env: dict[str, str]
) -> None:
    probe = tmp_path / "probe.py"
    probe.write_text(PROBE)
    path = tmp_path / "probe.launch.yaml"
    path.write_text(f'launch:\n- executable: {{cmd: "{sys.executable} {probe}", name: probe}}\n')
    checks = ["--expect-tf", "base_link:odom", "--expect-param", "/probe:rate=5"]
    checks += ["--expect-action", "/nav"]
    report = tmp_path / "r.xml"
    done = run_mlaunch(
        "test", str(path), "--hold", "0", *checks, "--junit", str(report), env=clean_env(),
        timeout=120,
    )  # fmt: skip
    assert done.returncode == 0, done.stdout + done.stderr
    assert "base_link -> odom through base_link -> odom" in _row(done.stdout, "TF links")
    assert "rate = 5" in _row(done.stdout, "parameter rate")
    assert _row(done.stdout, "action server /nav").startswith("ok")
    wrong = ["--expect-param", "/probe:rate=6", "--within", "15", "--expect-tf", "odom:map"]
    done = run_mlaunch("test", str(path), "--hold", "0", *wrong, env=clean_env(), timeout=120)
    assert done.returncode == 1, done.stdout + done.stderr
    assert "rate = 5" in _row(done.stdout, "parameter rate of /probe is 6")


def test_the_verdict_as_json(tmp_path: Path) -> None:
    path = tmp_path / "says.launch.py"
    path.write_text(SAYS % {"line": "[ERROR] [talker]: boom", "let": ""})
    done = run_mlaunch(
        "test", str(path), "--hold", "0", "--no-errors", "--format", "json", env=clean_env()
    )
    assert done.returncode == 1, done.stderr
    verdict = json.loads(done.stdout)
    assert verdict["passed"] is False and verdict["file"] == str(path)
    failed = [c for c in verdict["checks"] if c["status"] == "failed"]
    assert [c["check"] for c in failed] == ["forbid"]
    assert "boom" in failed[0]["seen"]
    assert verdict["window"]["hold"] == 0 and "watched_after_ready" in verdict["window"]
    assert "boom" in "\n".join(verdict["output"]["talker-1"])
    assert verdict["ros_domain_id"].isdigit()


FLAKY = '''
import sys
from launch import LaunchDescription
from launch.actions import ExecuteProcess

CODE = """
import os, time
path = %r
n = int(open(path).read()) if os.path.exists(path) else 0
open(path, 'w').write(str(n + 1))
print('run', n, flush=True)
time.sleep(60) if n %% 2 == 0 else os._exit(3)
"""


def generate_launch_description():
    return LaunchDescription([ExecuteProcess(cmd=[sys.executable, "-c", CODE], name="flaky")])
'''


def test_repeat_reports_flakiness_per_check(tmp_path: Path) -> None:
    path = tmp_path / "flaky.launch.py"
    path.write_text(FLAKY % str(tmp_path / "count"))
    report = tmp_path / "r.xml"
    args = ("--repeat", "4", "--hold", "0", "--expect-output", "flaky:run", "--junit", str(report))
    done = run_mlaunch("test", str(path), *args, env=clean_env(), timeout=120)
    assert done.returncode == 1, done.stdout + done.stderr
    assert f"flakiness over 4 runs: {path}" in done.stdout
    flakiness = done.stdout[done.stdout.index("flakiness over") :].splitlines()
    rows = {line.split(None, 2)[2]: line.split()[:2] for line in flakiness[1:] if line.strip()}
    assert rows["process flaky-1 starts and keeps running"] == ["FLAKY", "2/4"]
    assert rows["output of flaky matches /run/"] == ["ok", "4/4"]
    assert len(ET.parse(report).getroot().findall("testsuite")) == 4
