"""Each `mlaunch test` run, launch_test file and pytest-run launch test gets a ROS domain of its
own when the user set none; `mlaunch test FILE... -j N` runs several at once with one report
(issue 32 item 2)."""

from __future__ import annotations

import os
import re
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from procutil import REPO, clean_env, run_mlaunch

from mlaunch.ros import domain

# A process that says which domain and discovery range it was given, then stays up.
SAYS_DOMAIN = """
import sys
from launch import LaunchDescription
from launch.actions import ExecuteProcess

CODE = (
    "import os, time; print('DOMAIN=' + os.environ.get('ROS_DOMAIN_ID', '-') + ' RANGE='"
    " + os.environ.get('ROS_AUTOMATIC_DISCOVERY_RANGE', '-'), flush=True); %(end)s"
)

def generate_launch_description():
    return LaunchDescription([ExecuteProcess(cmd=[sys.executable, "-c", CODE], name="dom")])
"""
STAYS = "time.sleep(60)"

LAUNCH_TEST = """
import os
import sys
import unittest

import launch
import launch.actions
import launch_testing.actions
%(imports)s

CODE = "import os; print('DOMAIN=' + os.environ.get('ROS_DOMAIN_ID', '-'), flush=True)"


def generate_test_description():
    dom = launch.actions.ExecuteProcess(cmd=[sys.executable, "-c", CODE], name="dom")
    return launch.LaunchDescription([%(first)s dom, launch_testing.actions.ReadyToTest()]), {
        "dom": dom
    }


class TestDomain(unittest.TestCase):
    def test_the_process_and_the_test_share_a_domain_of_their_own(self, proc_output, dom):
        mine = os.environ.get("ROS_DOMAIN_ID", "")
        assert mine.isdigit() and mine != "%(user)s", mine
        proc_output.assertWaitFor("DOMAIN=" + mine, process=dom, timeout=10, stream="stdout")
        print("TEST-DOMAIN=" + mine)
"""


def _env(**extra: str) -> dict[str, str]:
    env = clean_env(**extra)
    if "ROS_DOMAIN_ID" not in extra:
        env.pop("ROS_DOMAIN_ID", None)
    env.pop("ROS_AUTOMATIC_DISCOVERY_RANGE", None)
    env.pop("ROS_LOCALHOST_ONLY", None)
    return env


def _says_domain(tmp_path: Path, name: str = "dom.launch.py", end: str = STAYS) -> Path:
    path = tmp_path / name
    path.write_text(SAYS_DOMAIN % {"end": end})
    return path


def test_a_run_gets_a_domain_of_its_own_and_says_which(tmp_path: Path) -> None:
    path = _says_domain(tmp_path)
    report = tmp_path / "report.xml"
    args = ("test", str(path), "--hold", "0", "--expect-output", "dom:DOMAIN=")
    done = run_mlaunch(*args, "--junit", str(report), env=_env())
    assert done.returncode == 0, done.stdout + done.stderr
    said = re.search(r"ROS domain (\d+) \(a domain of its own, discovery LOCALHOST\)", done.stdout)
    assert said, done.stdout
    seen = re.search(r"DOMAIN=(\d+) RANGE=(\S+)", done.stdout)
    assert seen and seen[1] == said[1] and seen[2] == "LOCALHOST", done.stdout
    assert said[1] != "0"
    suite = ET.parse(report).getroot().find("testsuite")
    assert suite is not None
    properties = {p.get("name"): p.get("value") for p in suite.iter("property")}
    assert properties["ros_domain_id"] == said[1]


def test_a_domain_the_user_set_is_kept(tmp_path: Path) -> None:
    path = _says_domain(tmp_path)
    args = ("test", str(path), "--hold", "0", "--expect-output", "dom:DOMAIN=")
    done = run_mlaunch(*args, env=_env(ROS_DOMAIN_ID="7"))
    assert done.returncode == 0, done.stdout + done.stderr
    assert "DOMAIN=7 RANGE=-" in done.stdout
    assert "ROS domain 7 (ROS_DOMAIN_ID set by the user, discovery SUBNET)" in done.stdout


def test_claims_skip_held_domains_and_end_with_their_holder(tmp_path: Path) -> None:
    pattern = str(tmp_path / "d-{}.lock")
    held = [domain.try_lock(pattern.format(i)) for i in domain.SAFE if i != 42]
    try:
        environ: dict[str, str] = {}
        claim = domain.isolate(environ, pattern)
        assert claim is not None and claim.domain == 42
        assert environ == {"ROS_DOMAIN_ID": "42", "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}
        assert domain.held("42")
        # Held: the next claim goes past the safe ids; released, 42 is free again.
        second = domain.claim(pattern)
        assert second.domain in domain.HIGH
        second.release()
        claim.release()
        assert not domain.held("42")
        again = domain.claim(pattern)
        assert again.domain == 42
        again.release()
    finally:
        for fd in held:
            if fd is not None:
                os.close(fd)
    assert domain.isolate({"ROS_DOMAIN_ID": "3"}, pattern) is None


def test_several_files_at_once_each_isolated_one_report(tmp_path: Path) -> None:
    files = [_says_domain(tmp_path, f"ok{i}.launch.py") for i in range(3)]
    bad = _says_domain(tmp_path, "bad.launch.py", end="raise SystemExit(3)")
    report = tmp_path / "all.xml"
    args = [str(f) for f in [*files, bad]]
    done = run_mlaunch(
        "test", *args, "-j", "4", "--hold", "0", "--junit", str(report), env=_env(), timeout=120
    )
    out = done.stdout + done.stderr
    assert done.returncode == 1, out
    assert "mlaunch test: 3 of 4 passed in " in out
    domains = re.findall(r"\[\d/4\] PASSED in [\d.]+ s: \S+ \(ROS domain (\d+)\)", out)
    assert len(domains) == 3 and len(set(domains)) == 3, out
    assert f"===== {bad}: FAILED" in out and "exited with status 3" in out
    root = ET.parse(report).getroot()
    suites = root.findall("testsuite")
    assert sorted(s.get("name", "") for s in suites) == sorted(
        f"mlaunch test {Path(a).name}" for a in args
    )
    assert root.get("failures") == "1"


def test_several_files_with_one_that_does_not_load(tmp_path: Path) -> None:
    good = _says_domain(tmp_path, "good.launch.py")
    broken = tmp_path / "broken.launch.yaml"
    broken.write_text('launch:\n- executable: {cmd: "echo $(var nope)"}\n')
    report = tmp_path / "all.xml"
    done = run_mlaunch(
        "test", str(good), str(broken), "--hold", "0", "--junit", str(report), env=_env()
    )
    assert done.returncode == 1, done.stdout + done.stderr
    assert "ERROR (exit status 2)" in done.stdout and "'nope' does not exist" in done.stdout
    suites = ET.parse(report).getroot().findall("testsuite")
    stand_in = next(s for s in suites if s.get("name") == "mlaunch test broken.launch.yaml")
    assert stand_in.get("failures") == "1"


def test_bad_job_counts_are_usage_errors(tmp_path: Path) -> None:
    path = _says_domain(tmp_path)
    done = run_mlaunch("test", str(path), "-j", "0", env=_env())
    assert done.returncode == 2 and "-j '0'" in done.stderr, done.stderr


@pytest.mark.parametrize("how", ["launch_test", "pytest"])
def test_a_launch_test_file_gets_a_domain_of_its_own(tmp_path: Path, how: str) -> None:
    values = {"imports": "import pytest", "first": "", "user": "-"}
    if how == "launch_test":
        path = tmp_path / "dom.test.py"
        path.write_text(LAUNCH_TEST % values)
        done = run_mlaunch("test", str(path), env=_env())
    else:
        path = tmp_path / "test_dom_launch.py"
        text = LAUNCH_TEST % values
        text = text.replace(
            "def generate_test_description",
            "@pytest.mark.launch_test\ndef generate_test_description",
        )
        path.write_text(text)
        done = subprocess.run(
            [sys.executable, "-m", "pytest", "-p", "no:cacheprovider", "-q", "-s", str(path)],
            capture_output=True, text=True, env=_env(), cwd=tmp_path, timeout=120,
        )  # fmt: skip
    assert done.returncode == 0, done.stdout + done.stderr
    assert re.search(r"TEST-DOMAIN=\d+", done.stdout + done.stderr), done.stdout + done.stderr


def test_enable_rmw_isolation_gives_the_launch_a_domain_of_its_own(tmp_path: Path) -> None:
    values = {
        "imports": "from launch_testing_ros.actions import EnableRmwIsolation",
        "first": "EnableRmwIsolation(),",
        "user": "9",
    }
    path = tmp_path / "iso.test.py"
    path.write_text(LAUNCH_TEST % values)
    done = run_mlaunch("test", str(path), env=_env(ROS_DOMAIN_ID="9"))
    assert done.returncode == 0, done.stdout + done.stderr
    check = run_mlaunch(str(path), "--check", env=_env())
    assert "Jazzy has no module 'launch_testing_ros.actions'" in check.stdout, check.stdout


def test_the_jtbot_passes_in_a_domain_of_its_own() -> None:
    done = run_mlaunch(
        "test", str(REPO / "launches/jtbot_sim.launch.py"), "--hold", "1", env=_env(), timeout=120
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert "(a domain of its own, discovery LOCALHOST)" in done.stdout


@pytest.mark.parametrize("shared", [True, False])
def test_a_test_sharing_its_domain_with_another_says_so(
    tmp_path: Path, ros_env: dict[str, str], shared: bool
) -> None:
    pytest.importorskip("rclpy")
    path = _says_domain(tmp_path)
    env = _env(ROS_DOMAIN_ID=ros_env["ROS_DOMAIN_ID"]) if shared else _env()
    # Both wait for a topic nobody publishes, so both look at their graph the whole time.
    args = ["test", str(path), "--hold", "0", "--expect-topic", "/nobody", "--within", "15"]
    runs = [
        subprocess.Popen(
            [sys.executable, "-m", "mlaunch", *args],
            env=env,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
        )
        for _ in range(2)
    ]
    outs = [run.communicate(timeout=120)[0] for run in runs]
    for out in outs:
        assert "topic /nobody publishes" in out, out
        assert ("another test shares this ROS domain" in out) == shared, out


def test_launch_testing_files_run_at_once_too(tmp_path: Path) -> None:
    values = {"imports": "import pytest", "first": "", "user": "-"}
    files = []
    for name in ("a.test.py", "b.test.py"):
        files.append(tmp_path / name)
        files[-1].write_text(LAUNCH_TEST % values)
    report = tmp_path / "all.xml"
    args = [str(f) for f in files]
    done = run_mlaunch("test", *args, "-j", "2", "--junit", str(report), env=_env(), timeout=120)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "mlaunch test: 2 of 2 passed" in done.stdout
    assert len(ET.parse(report).getroot().findall("testsuite")) == 2
