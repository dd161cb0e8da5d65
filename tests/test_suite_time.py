"""benchmarks/suite_time.py: where the suite's time goes, from each test's start, end and CPU."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parent.parent / "benchmarks"
sys.path.insert(0, str(BENCH))
import suite_time  # noqa: E402


def _row(worker: str, nodeid: str, start: float, end: float, cpu: float) -> dict[str, object]:
    return {"worker": worker, "id": nodeid, "start": start, "end": end,
            "cpu_self": 0.1, "cpu_children": cpu - 0.1}  # fmt: skip


def test_the_summary_names_idle_workers_and_the_costly_files() -> None:
    rows = [
        _row("gw0", "tests/test_a.py::one", 100.0, 110.0, 2.0),
        _row("gw0", "tests/test_a.py::two", 115.0, 120.0, 1.0),  # 5 s idle before it
        _row("gw1", "tests/test_b.py::three", 100.0, 130.0, 0.5),  # ends last
    ]
    summary = suite_time.summarize(rows)
    assert summary["tests"] == 3 and summary["span_s"] == 30.0 and summary["summed_s"] == 45.0
    assert summary["workers"]["gw0"] == {
        "tests": 2, "busy_s": 15.0, "idle_between_s": 5.0, "idle_at_end_s": 10.0
    }  # fmt: skip
    assert summary["workers"]["gw1"]["idle_at_end_s"] == 0.0
    a = summary["files"]["tests/test_a.py"]
    assert a["tests"] == 2 and a["s"] == 15.0 and abs(a["cpu_s"] - 3.0) < 1e-9
    assert summary["longest"][0]["id"] == "tests/test_b.py::three"
    assert summary["costliest"][0]["id"] == "tests/test_a.py::one"
    assert summary["last_to_end"][0]["id"] == "tests/test_b.py::three"


def test_a_run_writes_each_test_s_line_and_the_report(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    tests = tmp_path / "test_tiny.py"
    tests.write_text("def test_one():\n    pass\n\ndef test_two():\n    assert 1 + 1 == 2\n")
    out = tmp_path / "figures.json"
    status = suite_time.main(["--workers", "0", "--keep", str(tmp_path / "tl"), "--json",
                              str(out), "--", str(tests)])  # fmt: skip
    assert status == 0
    lines = (tmp_path / "tl" / "tl-main.jsonl").read_text().splitlines()
    assert [json.loads(line)["id"].split("::")[1] for line in lines] == ["test_one", "test_two"]
    figures = json.loads(out.read_text())
    assert figures["summary"]["tests"] == 2 and figures["status"] == 0
    assert "suite: 2 tests" in capsys.readouterr().out
