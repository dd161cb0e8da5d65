"""A pytest plugin for benchmarks/suite_time.py: one JSON line per test, per xdist worker.

Each line: the test's id, its start and end (wall clock, so the workers' lines share one time
line), the CPU it cost the worker itself and the CPU of the children the worker reaped while it
ran. Written to SUITE_TIMELINE_DIR/tl-<worker>.jsonl. It wraps the test inside the serial lock
(conftest.py's wrapper is outermost), so a wait for that lock is idle time between two tests.
"""

from __future__ import annotations

import json
import os
import time
from collections.abc import Generator
from typing import IO

import pytest

_out: IO[str] | None = None


def _file() -> IO[str]:
    global _out
    if _out is None:
        worker = os.environ.get("PYTEST_XDIST_WORKER", "main")
        path = os.path.join(os.environ["SUITE_TIMELINE_DIR"], f"tl-{worker}.jsonl")
        _out = open(path, "a", buffering=1)  # noqa: SIM115 (open for the worker's life)
    return _out


@pytest.hookimpl(wrapper=True)
def pytest_runtest_protocol(
    item: pytest.Item, nextitem: pytest.Item | None
) -> Generator[None, object, object]:
    start, before = time.time(), os.times()
    try:
        return (yield)
    finally:
        end, after = time.time(), os.times()
        line = {
            "id": item.nodeid,
            "start": start,
            "end": end,
            "cpu_self": after.user - before.user + after.system - before.system,
            "cpu_children": after.children_user
            - before.children_user
            + after.children_system
            - before.children_system,
        }
        _file().write(json.dumps(line) + "\n")
