"""Twenty pages on the launch panel do not change the run's output latency (issue 36).

The pages are opened as the panel's script opens them (the state stream and a log view of the
printing process; a quarter never read, as stuck tabs), by benchmarks/dashboard_load.py, which
also measures what they cost mlaunch's CPU. Each of the printing process's lines carries the
time it was printed, and mlaunch's stdout is read as it comes: the delay is measured, windows
without and with the pages alternate so that load from elsewhere hits both.
"""

from __future__ import annotations

import signal
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO / "benchmarks"))

import dashboard_load as load  # noqa: E402


@pytest.mark.serial  # output delays, in milliseconds
@pytest.mark.timeout(120)
def test_twenty_pages_do_not_change_the_output_latency(tmp_path: Path) -> None:
    proc, stamps = load.start(tmp_path)
    try:
        results: dict[int, list[dict[str, float]]] = {0: [], 20: []}
        for pages in (0, 20, 0, 20):
            results[pages].append(load.window(proc, stamps, stamps.port, pages, 3.0))
        assert proc.poll() is None
    finally:
        proc.send_signal(signal.SIGINT)
        proc.wait(30)
    alone = {k: max(r[k] for r in results[0]) for k in ("median_ms", "p95_ms")}
    loaded = {k: min(r[k] for r in results[20]) for k in ("median_ms", "p95_ms")}
    print(f"without pages {results[0]}\nwith 20 pages {results[20]}")
    # every line arrived in each window (one each 10 ms: ~300 in 3 s)
    assert all(r["lines"] > 100 for rs in results.values() for r in rs), results
    # the pages were served: states and the log view's lines (~100 a second) reached them
    assert all(r["received"] > 15 * 3 * 1000 for r in results[20]), results
    assert loaded["median_ms"] <= 2 * alone["median_ms"] + 5.0, results
    assert loaded["p95_ms"] <= alone["p95_ms"] + 25.0, results
