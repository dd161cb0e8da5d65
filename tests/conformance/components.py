"""The differential harness for composable nodes: the LoadNode requests a launcher sends.

A component case is a launch file in ``component_cases/`` whose containers are the recording
container (``recording_container.py``, installed as ``conf_pkg``'s ``recording_container``).
Its first line says how many requests the run sends in all (``loads: N``) and may give launch
arguments (``args: a:=1``). A run starts the launcher, waits (with a deadline) until the
containers recorded N requests and the launcher logged N answers (loaded or failed), then
stops it with SIGINT, as a user would.

The summary of a run (``summarize``) is what the two launchers must agree on:

- ``loads``: per container (its full name), the requests it received, in the order received,
  whole: package, plugin, name, namespace, log level, remap rules, parameters and extra
  arguments as [name, ParameterType, value];
- ``log``: the lines of the launcher's ``launch_ros`` loggers (a load's success or failure,
  with the container's message) and its warnings of node names given twice, sorted, since
  loads into different containers race.

Order across containers is not compared (each container is loaded by its own thread in either
launcher); the cases send each container's requests from one action, whose order is defined.

The reference ros2 launch has no ``composition_interfaces`` of its own (only an import shim): the
one ./scripts/setup built for this venv is put on its PYTHONPATH and LD_LIBRARY_PATH, from a
folder holding only that package and its libraries so that nothing else of this venv shadows
the reference's own.
"""

from __future__ import annotations

import importlib.util
import json
import os
import re
import signal
import subprocess
import sys
from pathlib import Path
from typing import Any

import harness
from procutil import wait_until

HERE = Path(__file__).resolve().parent
CASES = HERE / "component_cases"
EXPECTED = HERE / "component_expected"
# The variables of the test's private ROS domain that both launchers are given.
ROS_VARIABLES = ("ROS_DOMAIN_ID", "ROS_AUTOMATIC_DISCOVERY_RANGE", "RMW_IMPLEMENTATION")
# A launcher's launch_ros log line: '[LEVEL] [launch_ros...]: message'.
_LAUNCH_ROS_LINE = re.compile(r"^\[(INFO|WARNING|ERROR|DEBUG)\] \[(launch_ros[^\]]*)\]: (.*)$")
_ANSWER = re.compile(r"^(Loaded node '|Failed to load node ')")
# launch_ros's warning for a node name given twice (under the container's or the node's logger).
_ANY_LINE = re.compile(r"^\[(INFO|WARNING|ERROR|DEBUG)\] \[([^\]]+)\]: (.*)$")
_NAME_COUNT = re.compile(r"^there are now at least \d+ nodes with the name ")
# Deadlines: generous for a loaded 2-core machine; a healthy run takes a few seconds.
LOAD_DEADLINE = 60.0
STOP_DEADLINE = 20.0


def case_names() -> list[str]:
    return sorted(p.name for p in CASES.iterdir() if p.name.endswith(harness.SUFFIXES))


def case_options(name: str) -> dict[str, Any]:
    """``loads: N`` and ``args: ...`` from the case's first line."""
    first = (CASES / name).read_text(encoding="utf-8").splitlines()[0]
    match = re.search(r"loads:\s*(\d+)", first)
    if not match:
        raise ValueError(f"{name}: the first line must say 'loads: N' (requests the run sends)")
    args = re.search(r"args:((?:\s+\S+:=\S*)+)", first)
    return {"loads": int(match.group(1)), "args": args.group(1).split() if args else []}


def install_container(prefix: Path) -> None:
    """``lib/conf_pkg/recording_container``: this venv's interpreter on the recorder.

    Started by either launcher, it must run on this venv's rclpy whatever the launcher's
    environment says: the ROS wheels' start-up hook re-executes the interpreter with its own
    library path unless told it already did, and the reference's environment tells it so."""
    program = prefix / "lib" / harness.PACKAGE / "recording_container"
    script = HERE / "recording_container.py"
    program.write_text(
        "#!/bin/sh\n"
        "exec env -u _ROS_WHEELS_BOOTSTRAP_COMPLETE -u LD_LIBRARY_PATH -u PYTHONPATH"
        f' {sys.executable} {script} "$@"\n'
    )
    program.chmod(0o755)


def interfaces_overlay(root: Path) -> dict[str, str]:
    """PYTHONPATH and LD_LIBRARY_PATH folders holding only this venv's composition_interfaces."""
    spec = importlib.util.find_spec("composition_interfaces")
    if spec is None or spec.origin is None:
        raise RuntimeError("composition_interfaces is not built: run ./scripts/setup")
    package = Path(spec.origin).parent
    python, lib = root / "overlay" / "python", root / "overlay" / "lib"
    python.mkdir(parents=True)
    lib.mkdir()
    (python / "composition_interfaces").symlink_to(package)
    # The wheel installs the package's libraries in the venv's lib/ (rosidl's layout).
    for library in (Path(sys.prefix) / "lib").glob("libcomposition_interfaces__*.so"):
        (lib / library.name).symlink_to(library)
    return {"PYTHONPATH": str(python), "LD_LIBRARY_PATH": str(lib)}


# What rmw_fastrtps says when a container's service could not send an answer in time (a loaded
# machine): the answer is lost, the launcher waits for it forever, and the run says nothing of
# the launcher.
_DROPPED = "failed to send response"


class DroppedAnswer(AssertionError):
    """The middleware dropped a container's answer: this run of the case shows nothing."""


def run_case(
    launcher: str,
    name: str,
    work: Path,
    reference: dict[str, str] | None,
    ros_env: dict[str, str],
) -> dict[str, Any]:
    """Run component case ``name`` under ``launcher`` ('ros2' or 'mlaunch'); return its summary.

    A run in which the middleware dropped an answer is run once more (in a folder of its own).
    """
    try:
        return _run_once(launcher, name, work, reference, ros_env)
    except DroppedAnswer as dropped:
        print(f"run again: {dropped.args[0].splitlines()[0]}", file=sys.stderr)
        again = work / "again"
        again.mkdir()
        return _run_once(launcher, name, again, reference, ros_env)


def _run_once(
    launcher: str,
    name: str,
    work: Path,
    reference: dict[str, str] | None,
    ros_env: dict[str, str],
) -> dict[str, Any]:
    opts = case_options(name)
    prefix = harness.make_prefix(work, CASES)
    install_container(prefix)
    records = work / "records"
    records.mkdir()
    env = harness.base_environ(prefix, records, reference if launcher == "ros2" else None)
    env.update({k: ros_env[k] for k in ROS_VARIABLES if k in ros_env})
    if launcher == "ros2":
        overlay = interfaces_overlay(work)
        env["PYTHONPATH"] = overlay["PYTHONPATH"]
        env["LD_LIBRARY_PATH"] = os.pathsep.join(
            p for p in (env.get("LD_LIBRARY_PATH"), overlay["LD_LIBRARY_PATH"]) if p
        )
    elif "PYTHONPATH" in os.environ:
        env["PYTHONPATH"] = os.environ["PYTHONPATH"]  # the mlaunch this test imports
    argv = harness.launcher_argv(launcher, name, prefix, opts["args"], False)
    if launcher == "ros2":
        argv[0] = harness.shutil.which("ros2", path=env["PATH"]) or "ros2"
    out_path = work / "launcher.out"
    loads_path = records / "loads.jsonl"
    with open(out_path, "wb") as out:
        proc = subprocess.Popen(
            argv,
            env=env,
            cwd=str(work),
            stdin=subprocess.DEVNULL,
            stdout=out,
            stderr=subprocess.STDOUT,
            start_new_session=True,
        )
    try:

        def answered() -> bool:
            loads = _lines(loads_path)
            answers = [m for m in _launch_ros_lines(out_path) if _ANSWER.match(m[2])]
            return (
                proc.poll() is not None
                or (len(loads) >= opts["loads"] and len(answers) >= opts["loads"])
                or _DROPPED in out_path.read_text(encoding="utf-8", errors="replace")
            )

        done = wait_until(answered, LOAD_DEADLINE, interval=0.05)
        _stop(proc)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    text = out_path.read_text(encoding="utf-8", errors="replace")
    summary = summarize(_lines(loads_path), text)
    if len(summary["log"]) < opts["loads"] and _DROPPED in text:
        raise DroppedAnswer(
            f"{launcher} on {name}: the middleware dropped an answer: {text[-4000:]}"
        )
    if not done or len(summary["log"]) < opts["loads"]:
        raise AssertionError(
            f"{launcher} on {name}: expected {opts['loads']} requests and answers within"
            f" {LOAD_DEADLINE:.0f} s, got {sum(map(len, summary['loads'].values()))} requests"
            f" and {len(summary['log'])} answers; its output:\n{text[-4000:]}"
        )
    return summary


def _stop(proc: subprocess.Popen[bytes]) -> None:
    """SIGINT to the launcher (Ctrl-C); its process group is killed if anything outlives that."""
    if proc.poll() is None:
        proc.send_signal(signal.SIGINT)
        try:
            proc.wait(STOP_DEADLINE)
        except subprocess.TimeoutExpired:
            pass
    # ros2 launch's children share its group; a container left behind would hold the domain.
    if not wait_until(lambda: _group_gone(proc.pid), STOP_DEADLINE):
        os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()


def _group_gone(pgid: int) -> bool:
    try:
        os.killpg(pgid, 0)
    except ProcessLookupError:
        return True
    return False


def _lines(path: Path) -> list[str]:
    if not path.exists():
        return []
    return [line for line in path.read_text(encoding="utf-8").splitlines() if line.strip()]


def _launch_ros_lines(path: Path) -> list[tuple[str, str, str]]:
    text = path.read_text(encoding="utf-8", errors="replace") if path.exists() else ""
    out = []
    for line in text.splitlines():
        match = _LAUNCH_ROS_LINE.match(line.rstrip("\r"))
        if match:
            level, logger, message = match.groups()
            out.append((level, logger, message))
    return out


def summarize(loads: list[str], text: str) -> dict[str, Any]:
    per_container: dict[str, list[dict[str, Any]]] = {}
    for line in loads:
        record = json.loads(line)
        per_container.setdefault(record.pop("container"), []).append(record)
    log = []
    for raw in text.splitlines():
        match = _LAUNCH_ROS_LINE.match(raw.rstrip("\r")) or _ANY_LINE.match(raw.rstrip("\r"))
        if match:
            level, logger, message = match.groups()
            if logger.startswith("launch_ros") or _NAME_COUNT.match(message):
                log.append(f"{level} [{logger}] {message}")
    return {"loads": per_container, "log": sorted(log)}


def expected(name: str) -> dict[str, Any] | None:
    return harness.expected(name, EXPECTED)


def write_expected(name: str, summary: dict[str, Any]) -> None:
    harness.write_expected(name, summary, EXPECTED)
