"""Shared by the tests of --print --format json: the launch files, running mlaunch for a plan,
validating it against the shipped schema, and a demo package whose program reports what it got."""

from __future__ import annotations

import json
import os
import re
import sys
import textwrap
from pathlib import Path
from typing import Any

import jsonschema
import pytest
from procutil import REPO, clean_env, install_package, run_mlaunch

from mlaunch.schemas import load_plan_schema

LAUNCHES = REPO / "launches"
PREFIX = LAUNCHES / "examples" / "prefix"
# Launch files that declare arguments without defaults (parts meant to be included).
REQUIRED_ARGUMENTS = {
    "logger.launch.xml": ["source:=driver"],
    "sensors.launch.yaml": ["camera:=front"],
}
PY = sys.executable
LAUNCH_FILES = sorted(
    p for p in LAUNCHES.rglob("*") if p.is_file() and re.search(r"\.launch(\.\w+)?$", p.name)
)


def launch_id(path: Path) -> str:
    return str(path.relative_to(LAUNCHES))


@pytest.fixture
def env(tmp_path: Path) -> dict[str, str]:
    """mlaunch's environment: a private log folder and the examples' install prefix."""
    return clean_env(ROS_LOG_DIR=str(tmp_path / "log"), AMENT_PREFIX_PATH=str(PREFIX))


def plan_of(*args: str, env: dict[str, str]) -> dict[str, Any]:
    done = run_mlaunch(*args, "--print", "--format", "json", env=env)
    assert done.returncode == 0, done.stderr
    document: dict[str, Any] = json.loads(done.stdout)
    return document


def validate(document: dict[str, Any]) -> None:
    validator = jsonschema.Draft202012Validator(load_plan_schema())
    errors = sorted(validator.iter_errors(document), key=lambda e: list(e.path))
    assert not errors, "\n".join(f"{list(e.path)}: {e.message[:300]}" for e in errors[:5])


def absolute_origin(origin: dict[str, Any]) -> dict[str, Any]:
    """An origin with its file made absolute: the JSON writes it relative to the current folder
    when that climbs less than two folders, which depends on where the checkout is (/tmp/x in CI)."""
    return {**origin, "file": os.path.abspath(origin["file"])}


def processes(document: dict[str, Any]) -> dict[str, dict[str, Any]]:
    return {s["label"]: s for s in document["steps"] if s["kind"] == "process"}


def dump_package(tmp_path: Path) -> Path:
    """An install prefix with package 'demo' whose program writes its argv and the contents
    of its params files to argv.json beside it, then lives until stopped."""
    dump = textwrap.dedent(
        f"""\
            #!{PY}
            import json, os, sys, time
            argv = sys.argv
            files = [open(argv[i + 1]).read() for i, a in enumerate(argv) if a == "--params-file"]
            out = os.path.join(os.path.dirname(__file__), "argv.json")
            with open(out + ".part", "w") as f:
                json.dump({{"argv": argv, "files": files, "cwd": os.getcwd(),
                           "env": {{k: os.environ.get(k) for k in ("DUMP_MODE", "GONE")}}}}, f)
            os.rename(out + ".part", out)
            time.sleep(60)
            """
    )
    return install_package(tmp_path / "install", "demo", {"dump": dump})
