"""Native ROS 1 runs do what Debian's roslaunch does (the oracle, run side by side with its own
master): the environment a node gets, its command line when its args hold a ``__log:=``, the
stop ladder (SIGINT, SIGTERM after 15 s, SIGKILL 2 s later), the exit status when the parameter
server cannot be loaded; and the ROS 2 mapping of ``pass_all_args`` into a required arg."""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import xmlrpc.client
from pathlib import Path
from typing import Any

import pytest
from ports import free_port
from procutil import Running, wait_for
from ros1tree import SYSTEM_PYTHON, oracle, requires_roslaunch

REPO = Path(__file__).resolve().parent.parent

pytestmark = [
    requires_roslaunch,
    pytest.mark.skipif(
        shutil.which("rosmaster") is None or not os.access("/usr/lib/rosout/rosout", os.X_OK),
        reason="Debian's rosmaster and rosout are not installed",
    ),
    pytest.mark.timeout(180),
]

MANIFEST = (
    '<package format="2"><name>{}</name><version>0.0.0</version><description>t</description>'
    "<maintainer email='t@e.st'>t</maintainer><license>BSD</license></package>"
)
# Writes its environment and argv where DUMP_TO says, then waits to be stopped.
DUMP = """#!/bin/sh
env -0 > "$DUMP_TO.env.tmp" && mv "$DUMP_TO.env.tmp" "$DUMP_TO.env"
printf '%s\\0' "$@" > "$DUMP_TO.argv.tmp" && mv "$DUMP_TO.argv.tmp" "$DUMP_TO.argv"
exec sleep 600
"""
# Needs 8 s after SIGINT to shut down cleanly (roslaunch waits 15 s before SIGTERM).
SLOW = f"""#!{SYSTEM_PYTHON}
import os, signal, sys, time
def on_int(*_):
    time.sleep(8)
    open(os.environ["DUMP_TO"] + ".clean", "w").write("clean")
    sys.exit(0)
signal.signal(signal.SIGINT, on_int)
signal.signal(signal.SIGTERM, lambda *_: (open(os.environ["DUMP_TO"] + ".term", "w"), sys.exit(1)))
open(os.environ["DUMP_TO"] + ".up", "w").write("up")
while True:
    time.sleep(1)
"""


def tree(root: Path) -> dict[str, str]:
    """A package ``probe`` with the programs above; the environment of a shell for ROS 1 (no
    mlaunch venv in it, as the user's shell)."""
    pkg = root / "src" / "probe"
    pkg.mkdir(parents=True)
    (pkg / "package.xml").write_text(MANIFEST.format("probe"))
    for name, text in (("dump", DUMP), ("slow", SLOW)):
        (pkg / name).write_text(text)
        (pkg / name).chmod(0o755)
    env = {
        k: v
        for k, v in os.environ.items()
        if not k.startswith(("ROS_", "CMAKE_", "PYTHON", "VIRTUAL_ENV", "_ROS_WHEELS"))
        and k not in ("LD_LIBRARY_PATH", "RCUTILS_LOGGING_BUFFERED_STREAM")
    }
    env.update(
        PATH="/usr/bin:/bin",
        HOME=str(root),
        ROS_PACKAGE_PATH=str(root / "src"),
        ROS_HOME=str(root / "ros"),
        ROS_VERSION="1",
        ROS_DISTRO="noetic",
    )
    return env


def launcher(which: str) -> list[str]:
    if which == "roslaunch":
        return [SYSTEM_PYTHON, "/usr/bin/roslaunch"]
    # mlaunch as a user starts it: the venv's Python (whose ROS 2 wheels' bootstrap re-executes
    # it with their libraries on LD_LIBRARY_PATH)
    return [sys.executable, "-m", "mlaunch"]


def start(which: str, launch: Path, env: dict[str, str], out: Path) -> tuple[Running, int]:
    port = free_port()
    run_env = {**env, "ROS_MASTER_URI": f"http://localhost:{port}/", "DUMP_TO": str(out)}
    return Running([*launcher(which), str(launch)], env=run_env), port


def read_env(path: Path) -> dict[str, str]:
    items = path.read_bytes().decode().split("\0")
    return dict(item.split("=", 1) for item in items if "=" in item)


DUMPER = """<launch>
  <node name="dumper" pkg="probe" type="dump" ns="robot" args="one __log:=/tmp/mine.log two">
    <env name="EXTRA" value="x"/>
  </node>
</launch>
"""


def test_a_node_gets_roslaunch_s_environment_and_command_line(tmp_path: Path) -> None:
    env = tree(tmp_path)
    launch = tmp_path / "src" / "dump.launch"
    launch.write_text(DUMPER)
    seen: dict[str, tuple[dict[str, str], list[str]]] = {}
    for which in ("roslaunch", "mlaunch"):
        out = tmp_path / which
        run, port = start(which, launch, env, out)
        try:
            done = Path(f"{out}.argv")
            wait_for(done.exists, 60, f"{which}'s node: {run.text}")
        finally:
            run.signal(signal.SIGINT)
            run.finish(timeout=60)
        assert master_gone(port)
        argv = Path(f"{out}.argv").read_bytes().decode().split("\0")[:-1]
        seen[which] = (read_env(Path(f"{out}.env")), argv)
    (theirs, their_argv), (ours, our_argv) = seen["roslaunch"], seen["mlaunch"]
    # What differs on purpose (docs/ros1.md): each run's own master and file; mlaunch's run id
    # (no orphans) and line-buffered Python output through its pipe; roslaunch's own log file
    different = {"ROS_MASTER_URI", "DUMP_TO", "MLAUNCH_RUN_ID", "PYTHONUNBUFFERED"}
    different.add("ROS_LOG_FILENAME")
    assert {k: v for k, v in ours.items() if k not in different} == {
        k: v for k, v in theirs.items() if k not in different
    }
    assert ours["ROS_NAMESPACE"] == "/robot" and ours["EXTRA"] == "x"
    for name in ("LD_LIBRARY_PATH", "_ROS_WHEELS_BOOTSTRAP_COMPLETE", "VIRTUAL_ENV"):
        assert name not in ours, name
    # the __log:= of the args is dropped; each launcher's own comes last
    assert their_argv[:3] == ["one", "two", "__name:=dumper"], their_argv
    assert our_argv[:3] == their_argv[:3]
    assert [a for a in our_argv if a.startswith("__log:=")] == [our_argv[-1]]
    assert os.path.basename(our_argv[-1]) == os.path.basename(their_argv[-1])


SLOW_LAUNCH = """<launch>
  <node name="slow" pkg="probe" type="slow"/>
</launch>
"""


@pytest.mark.parametrize("which", ["roslaunch", "mlaunch"])
def test_a_node_gets_15_s_after_sigint_before_sigterm(tmp_path: Path, which: str) -> None:
    env = tree(tmp_path)
    launch = tmp_path / "src" / "slow.launch"
    launch.write_text(SLOW_LAUNCH)
    out = tmp_path / which
    run, port = start(which, launch, env, out)
    try:
        wait_for(lambda: Path(f"{out}.up").exists(), 60, f"the node up: {run.text}")
    finally:
        run.signal(signal.SIGINT)
        run.finish(timeout=60)
    assert master_gone(port)
    assert Path(f"{out}.clean").exists(), run.text  # shut down cleanly, 8 s after SIGINT
    assert not Path(f"{out}.term").exists(), run.text


def test_print_says_roslaunch_s_stop_ladder(tmp_path: Path) -> None:
    env = tree(tmp_path)
    launch = tmp_path / "src" / "slow.launch"
    launch.write_text(SLOW_LAUNCH)
    env["ROS_MASTER_URI"] = f"http://localhost:{free_port()}/"
    argv = [sys.executable, "-m", "mlaunch", str(launch), "--print"]
    done = subprocess.run(argv, env=env, capture_output=True, text=True, timeout=60, check=True)
    block = done.stdout.split("\nslow ", 1)[1]
    assert "stop:    SIGINT, SIGTERM after 15 s, SIGKILL after 2 s more" in block


@pytest.mark.parametrize(
    "bad",
    [
        '<param name="big" value="99999999999" type="int"/>',  # over XML-RPC's 32 bits
        '<rosparam param="p">{a: null, b: 1}</rosparam>',  # a YAML null: XML-RPC has no None
    ],
)
def test_a_parameter_server_that_cannot_be_loaded_ends_the_run_with_status_1(
    tmp_path: Path, bad: str
) -> None:
    env = tree(tmp_path)
    launch = tmp_path / "src" / "bad.launch"
    launch.write_text(f'<launch>\n  {bad}\n  <node name="d" pkg="probe" type="dump"/>\n</launch>\n')
    codes = {}
    for which in ("roslaunch", "mlaunch"):
        out = tmp_path / which
        run, port = start(which, launch, env, out)
        codes[which] = run.finish(timeout=90)
        assert master_gone(port)
        assert not Path(f"{out}.argv").exists(), run.text  # no node started
        if which == "mlaunch":
            assert "the ROS 1 parameter server could not be loaded" in run.text
    assert codes == {"roslaunch": 1, "mlaunch": 1}


OUTER = """<launch>
  <arg name="x" default="hello"/>
  <arg name="y" default="kept"/>
  <include file="$(dirname)/inner.launch" pass_all_args="true">
    <arg name="y" value="given"/>
  </include>
</launch>
"""
INNER = """<launch>
  <arg name="x"/>
  <arg name="y"/>
  <param name="got" value="$(arg x)-$(arg y)"/>
  <node name="n" pkg="probe" type="dump" args="--say $(arg x) $(arg y)"/>
</launch>
"""


def test_pass_all_args_reaches_a_required_arg_in_the_ros2_mapping(tmp_path: Path) -> None:
    env = tree(tmp_path)
    (tmp_path / "src" / "outer.launch").write_text(OUTER)
    (tmp_path / "src" / "inner.launch").write_text(INNER)
    theirs = oracle(tmp_path / "src" / "outer.launch", {}, env)
    assert theirs["nodes"][0]["args"] == "--say hello given"
    assert theirs["params"]["/got"] == ["str", "hello-given"]
    argv = [sys.executable, "-m", "mlaunch", "--ros2", "--print", "--format", "json"]
    done = subprocess.run(
        [*argv, str(tmp_path / "src" / "outer.launch")],
        env={**env, "ROS_VERSION": "2"},
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    plan: dict[str, Any] = json.loads(done.stdout)
    (node,) = [s for s in plan["steps"] if s["kind"] == "process"]
    assert node["argv"][1:4] == ["--say", "hello", "given"], node["argv"]


def test_print_in_a_ros1_shell_shows_the_nodes(tmp_path: Path) -> None:
    env = tree(tmp_path)
    launch = tmp_path / "src" / "dump.launch"
    launch.write_text(DUMPER.replace("<node", '<param name="/top" value="1"/>\n  <node', 1))
    env["ROS_MASTER_URI"] = f"http://localhost:{free_port()}/"
    argv = [sys.executable, "-m", "mlaunch", str(launch), "--print"]
    done = subprocess.run(argv, env=env, capture_output=True, text=True, timeout=60, check=True)
    text = done.stdout
    assert "once the parameter server is loaded, 2 node(s) start:" in text, text
    block = text.split("\ndumper ", 1)[1].split("\n\n", 1)[0]
    assert f"argv:    {tmp_path}/src/probe/dump one two __name:=dumper __log:=" in block, block
    assert "node:    /robot/dumper" in block
    assert "env:     EXTRA=x ROS_NAMESPACE=/robot" in block, block
    assert "  /top = 1 (int)" in text
    assert "<locals>" not in text and "roslaunch_params (the parameter server's loader)" in text
    data = subprocess.run(
        [*argv, "--format", "json"], env=env, capture_output=True, text=True, check=True
    )
    (nodes,) = [s for s in json.loads(data.stdout)["steps"] if s["kind"] == "ros1_nodes"]
    assert [n["name"] for n in nodes["nodes"]] == ["/rosout", "/robot/dumper"]
    assert nodes["nodes"][1]["env"] == {"EXTRA": "x", "ROS_NAMESPACE": "/robot"}


def master_gone(port: int) -> bool:
    try:
        xmlrpc.client.ServerProxy(f"http://localhost:{port}/").getPid("/t")
    except OSError:
        return True
    return False
