"""The README's GitHub Actions job, run here as far as a machine without GitHub can: its YAML is
a job with a matrix of launch files, JUnit uploaded always and the evidence on failure, and each
`run:` step of each matrix entry runs and passes (issue 32: the CI section)."""

from __future__ import annotations

import re
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import pytest
import yaml
from procutil import REPO, clean_env

README = REPO / "README.md"


def _job() -> dict[str, Any]:
    text = README.read_text()
    section = text[text.index("### In CI") :]
    block = re.search(r"```yaml\n(.*?)```", section, re.S)
    assert block, "the README's CI section has no yaml block"
    document = yaml.safe_load(block[1])
    ((name, job),) = document["jobs"].items()
    assert name == "launch-files"
    return dict(job)


def _entries() -> list[dict[str, str]]:
    return list(_job()["strategy"]["matrix"]["include"])


def test_the_job_uploads_junit_always_and_the_evidence_on_failure() -> None:
    job = _job()
    uploads = [s for s in job["steps"] if str(s.get("uses", "")).startswith("actions/upload")]
    conditions = {s["if"]: s["with"]["path"] for s in uploads}
    assert conditions["always()"].startswith("out/junit-")
    assert conditions["failure()"].startswith("out/evidence-")
    runs = [s["run"] for s in job["steps"] if "run" in s]
    assert any("--check" in r for r in runs)
    assert any(" -j " in r and "--junit" in r and "--artifacts" in r for r in runs)
    assert len(_entries()) >= 2


def _local(command: str, entry: dict[str, str], out: Path) -> str:
    """A `run:` step as this machine runs it: the matrix values put in, the venv's mlaunch as
    the interpreter running the tests has it, out/ in the test's folder."""
    for key, value in entry.items():
        command = command.replace("${{ matrix." + key + " }}", value)
    assert "${{" not in command, command
    command = command.replace(".venv/bin/mlaunch", f"{sys.executable} -m mlaunch")
    return command.replace("out/", f"{out}/")


@pytest.mark.parametrize("entry", _entries(), ids=lambda e: e["name"])
def test_each_matrix_entry_s_steps_pass_here(entry: dict[str, str], tmp_path: Path) -> None:
    env = clean_env()
    env.pop("ROS_DOMAIN_ID", None)  # as on a CI runner: each run claims a domain of its own
    steps = [s["run"] for s in _job()["steps"] if "run" in s and "scripts/setup" not in s["run"]]
    for step in steps:
        command = _local(step, entry, tmp_path)
        done = subprocess.run(
            ["bash", "-c", command], cwd=REPO, env=env, capture_output=True, text=True, timeout=300
        )
        assert done.returncode == 0, f"{command}\n{done.stdout}{done.stderr}"
    report = ET.parse(tmp_path / f"junit-{entry['name']}.xml").getroot()
    assert len(report.findall("testsuite")) == len(entry["files"].split())
    assert report.get("failures") == "0"
    assert (tmp_path / f"evidence-{entry['name']}").is_dir()
