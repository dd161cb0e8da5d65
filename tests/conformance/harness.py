"""The differential harness: run a case under a launcher and reduce what happened to comparable data.

A case is a small launch file in ``cases/`` (``NAME.launch.py``, ``.launch.yaml`` or ``.launch.xml``).
Its first line may carry options for the harness in a comment: ``args: a:=1 b:=2`` (command-line
launch arguments) and ``pkg`` (start it as ``PKG FILE`` instead of ``FILE``). Every case starts
the recorder (``recorder.py``), which writes down its argv, cwd, environment and params files.

The summary of a run (``summarize``) is what the two launchers must agree on:

- ``processes``: one entry per start, sorted (starts in one pass race each other), with argv,
  cwd, the environment variables that differ from what the launcher itself was given, the parsed
  contents of each ``--params-file`` and whether the standard streams were terminals;
- ``log``: the ``launch.user`` lines (``LogInfo``) in the order printed: event order;
- ``events``: per process label, the started / exited lines in order;
- ``output``: per process label, the process's lines that reached the screen (sorted: stdout and
  stderr are separate pipes);
- ``rc``: the launcher's exit status.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import yaml

HERE = Path(__file__).resolve().parent
CASES = HERE / "cases"
EXPECTED = HERE / "expected"
REPO = HERE.parent.parent
PACKAGE = "conf_pkg"
sys.path.insert(0, str(HERE.parent))  # tests/, when record.py runs this outside pytest
import reference  # noqa: E402
from reference import run_ros2  # noqa: E402

REFERENCE_ENV_SH = reference.ENV_SH
SUFFIXES = (".launch.py", ".launch.yaml", ".launch.xml")
# The same search path for both launchers (the reference puts its venv in front), so that
# FindExecutable and friends find the same programs here and on CI.
SYSTEM_PATH = "/usr/local/bin:/usr/bin:/bin"

# mlaunch sets these on every child on purpose (README: output is timely, nothing is orphaned).
# They are left out of the comparison only when they carry mlaunch's own value.
ON_PURPOSE_ENV = {
    "MLAUNCH_RUN_ID": None,
    "PYTHONUNBUFFERED": "1",
    "RCUTILS_LOGGING_BUFFERED_STREAM": "1",
}
# The ROS wheels in a venv set these when its interpreter starts (their .pth bootstrap), so any
# child of a venv's python has them: a property of the installation, not of the launcher.
# LC_CTYPE is set by Python's C-locale coercion in the recorder itself.
INTERPRETER_ENV = ("LD_LIBRARY_PATH", "_ROS_WHEELS_BOOTSTRAP_COMPLETE", "LC_CTYPE")
HARNESS_ENV = (
    "PATH",
    "HOME",
    "ROS_LOG_DIR",
    "AMENT_PREFIX_PATH",
    "CONF_RECORD_DIR",
    "NO_COLOR",
    "LC_ALL",
)
_LOG_LINE = re.compile(r"^\[(INFO|WARNING|ERROR|DEBUG)\] \[([^\]]+)\]: (.*)$")
_OUTPUT_LINE = re.compile(r"^\[([^\]\s]+)\] (.*)$")
_STARTED = re.compile(r"^process started with pid \[\d+\]$")
_FINISHED = re.compile(r"^process has finished cleanly \[pid \d+\]$")
_DIED = re.compile(r"^process has died \[pid \d+, exit code (-?\d+), cmd '.*'\]")


class _ParamsLoader(yaml.SafeLoader):
    """Reads launch_ros's params files, which write Python tuples with their YAML tag."""


def _tuple_as_list(loader: yaml.SafeLoader, node: yaml.SequenceNode) -> list[object]:
    return loader.construct_sequence(node)


_ParamsLoader.add_constructor("tag:yaml.org,2002:python/tuple", _tuple_as_list)


def case_names() -> list[str]:
    return sorted(p.name for p in CASES.iterdir() if p.name.endswith(SUFFIXES))


def case_options(name: str) -> dict[str, Any]:
    """The harness options on the first line of a case: ``args: ...`` and ``pkg``."""
    first = (CASES / name).read_text(encoding="utf-8").splitlines()[0]
    opts: dict[str, Any] = {"args": [], "pkg": False}
    match = re.search(r"args:((?:\s+\S+:=\S*)+)", first)
    if match:
        opts["args"] = match.group(1).split()
    opts["pkg"] = bool(re.search(r"\bpkg\b", first))
    return opts


def reference_environ() -> dict[str, str] | None:
    """The environment the reference ros2 launch runs in, or None where it is not built."""
    if not REFERENCE_ENV_SH.is_file():
        return None
    out = subprocess.run(
        ["bash", "-c", f"source {REFERENCE_ENV_SH} && env -0"],
        capture_output=True,
        check=True,
        env={"PATH": SYSTEM_PATH, "HOME": os.environ["HOME"]},
    ).stdout.decode()
    env = dict(item.split("=", 1) for item in out.split("\0") if "=" in item)
    return env if shutil.which("ros2", path=env.get("PATH")) else None


def make_prefix(root: Path, cases: Path = CASES) -> Path:
    """An ament prefix holding ``conf_pkg``: the recorder and every case under share/.../launch."""
    prefix = root / "prefix"
    index = prefix / "share" / "ament_index" / "resource_index" / "packages"
    index.mkdir(parents=True)
    (index / PACKAGE).write_text("")
    share = prefix / "share" / PACKAGE
    share.mkdir(parents=True)
    (share / "package.xml").write_text(
        f'<?xml version="1.0"?>\n<package format="3"><name>{PACKAGE}</name>'
        "<version>0.0.0</version><description>conformance recorder</description>"
        "<maintainer email='a@b.c'>m</maintainer><license>Apache-2.0</license></package>\n"
    )
    shutil.copytree(cases, share / "launch")
    lib = prefix / "lib" / PACKAGE
    lib.mkdir(parents=True)
    recorder = lib / "recorder"
    text = (HERE / "recorder.py").read_text(encoding="utf-8")
    recorder.write_text(f"#!{sys.executable}\n{text}")
    recorder.chmod(0o755)
    return prefix


def base_environ(prefix: Path, records: Path, reference: dict[str, str] | None) -> dict[str, str]:
    """What a launcher is given: the reference's variables (if any), the prefix, the record dir."""
    env = dict(reference) if reference else {"PATH": SYSTEM_PATH}
    env["HOME"] = os.environ["HOME"]
    env["ROS_LOG_DIR"] = str(records.parent / "log")
    env["AMENT_PREFIX_PATH"] = os.pathsep.join(
        [str(prefix), *([reference["AMENT_PREFIX_PATH"]] if reference else [])]
    )
    env["CONF_RECORD_DIR"] = str(records)
    env["NO_COLOR"] = "1"
    env["LC_ALL"] = "C.UTF-8"
    return env


def launcher_argv(launcher: str, name: str, prefix: Path, args: list[str], pkg: bool) -> list[str]:
    target = [PACKAGE, name] if pkg else [str(prefix / "share" / PACKAGE / "launch" / name)]
    if launcher == "ros2":
        return ["ros2", "launch", *target, *args]
    return [sys.executable, "-m", "mlaunch", *target, *args]


def run_case(
    launcher: str, name: str, work: Path, reference: dict[str, str] | None
) -> dict[str, Any]:
    """Run case ``name`` under ``launcher`` ('ros2' or 'mlaunch') in ``work``; return its summary."""
    prefix = make_prefix(work)
    if launcher == "mlaunch":
        return run_mlaunch_case(name, work, prefix)[0]
    opts = case_options(name)
    records = work / "records"
    records.mkdir()
    env = base_environ(prefix, records, reference)
    argv = launcher_argv(launcher, name, prefix, opts["args"], opts["pkg"])
    argv[0] = shutil.which("ros2", path=env["PATH"]) or "ros2"
    proc = run_ros2(argv, env=env, cwd=work, timeout=60)
    return _summary(proc, records, env, prefix, work)


def run_mlaunch_case(
    name: str,
    work: Path,
    prefix: Path,
    more: Sequence[str] = (),
    env_more: dict[str, str] | None = None,
) -> tuple[dict[str, Any], subprocess.CompletedProcess[str]]:
    """Run case ``name`` under mlaunch in ``work`` with the case files in ``prefix`` (again
    and again: its records are new each run), options ``more`` after the case's arguments and
    ``env_more`` in its environment; its summary, and what it printed."""
    opts = case_options(name)
    records = work / "records"
    shutil.rmtree(records, ignore_errors=True)
    records.mkdir()
    env = base_environ(prefix, records, None)
    if "PYTHONPATH" in os.environ:
        env["PYTHONPATH"] = os.environ["PYTHONPATH"]  # the mlaunch this test imports
    env.update(env_more or {})
    argv = launcher_argv("mlaunch", name, prefix, opts["args"], opts["pkg"])
    proc = subprocess.run(
        [*argv, *more],
        env=env,
        cwd=str(work),
        stdin=subprocess.DEVNULL,
        capture_output=True,
        text=True,
        timeout=60,
        start_new_session=True,
    )
    return _summary(proc, records, env, prefix, work), proc


def _summary(
    proc: subprocess.CompletedProcess[str],
    records: Path,
    env: dict[str, str],
    prefix: Path,
    work: Path,
) -> dict[str, Any]:
    lines = (
        (records / "records.jsonl").read_text().splitlines()
        if (records / "records.jsonl").exists()
        else []
    )
    return summarize(
        rc=proc.returncode,
        text=proc.stdout + proc.stderr,
        records=[json.loads(line) for line in lines],
        given=env,
        paths={str(prefix): "<prefix>", str(work): "<work>"},
    )


def _normalize(text: str, paths: dict[str, str]) -> str:
    for path, placeholder in sorted(paths.items(), key=lambda kv: -len(kv[0])):
        text = text.replace(path, placeholder)
    return text


def _process(
    record: dict[str, Any], given: dict[str, str], paths: dict[str, str]
) -> dict[str, Any]:
    argv = list(record["argv"])
    for i, arg in enumerate(argv[:-1]):
        if arg == "--params-file":
            argv[i + 1] = "<params-file>"
    env = {}
    for key, value in record["env"].items():
        if given.get(key) == value or key in INTERPRETER_ENV:
            continue
        if key in ON_PURPOSE_ENV and ON_PURPOSE_ENV[key] in (None, value):
            continue
        env[key] = _normalize(value, paths)
    for key in HARNESS_ENV:  # what every launcher is given, whatever else it has
        if key not in record["env"]:
            env[key] = "<unset>"
    params = []
    for text in record["params_files"]:
        try:
            params.append(yaml.load(text, Loader=_ParamsLoader))
        except yaml.YAMLError:
            params.append(text)
    return {
        "argv0": record["argv0"],
        "argv": [_normalize(a, paths) for a in argv],
        "cwd": _normalize(record["cwd"], paths),
        "env": env,
        "params": params,
        "tty": [record["stdin_tty"], record["stdout_tty"], record["stderr_tty"]],
    }


def summarize(
    *,
    rc: int,
    text: str,
    records: list[dict[str, Any]],
    given: dict[str, str],
    paths: dict[str, str],
) -> dict[str, Any]:
    log: list[str] = []
    events: dict[str, list[str]] = {}
    output: dict[str, list[str]] = {}
    for raw in text.splitlines():
        line = _normalize(raw.rstrip("\r"), paths)
        match = _LOG_LINE.match(line)
        if match:
            level, logger, message = match.groups()
            if logger == "launch.user":
                log.append(f"{level} {message}")
            elif _STARTED.match(message):
                events.setdefault(logger, []).append("started")
            elif _FINISHED.match(message):
                events.setdefault(logger, []).append("exit 0")
            elif died := _DIED.match(message):
                events.setdefault(logger, []).append(f"exit {died.group(1)}")
            continue
        match = _OUTPUT_LINE.match(line)
        if match:
            output.setdefault(match.group(1), []).append(match.group(2))
    processes = [_process(r, given, paths) for r in records]
    processes.sort(key=lambda p: json.dumps(p, sort_keys=True))
    return {
        "rc": rc,
        "processes": processes,
        "log": log,
        "events": events,
        "output": {label: sorted(lines) for label, lines in output.items()},
    }


def expected(name: str, folder: Path = EXPECTED) -> dict[str, Any] | None:
    """The recording of case ``name`` in ``folder``, None when there is none."""
    path = folder / f"{name}.json"
    if not path.exists():
        return None
    result: dict[str, Any] = json.loads(path.read_text(encoding="utf-8"))
    return result


def write_expected(name: str, summary: dict[str, Any], folder: Path = EXPECTED) -> None:
    folder.mkdir(exist_ok=True)
    text = json.dumps(summary, indent=1, sort_keys=True) + "\n"
    (folder / f"{name}.json").write_text(text, encoding="utf-8")


def with_known_differences(
    names: list[str], known: dict[str, str], raises: type[BaseException] | None = None
) -> list[Any]:
    """Cases as pytest parameters, each known difference a strict xfail with its reason (that
    fails only by raising ``raises``, when given: any other failure is a failure)."""
    import pytest

    return [
        pytest.param(name, marks=pytest.mark.xfail(strict=True, reason=known[name], raises=raises))
        if name in known
        else name
        for name in names
    ]
