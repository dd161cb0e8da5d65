"""The launch panel (--dashboard, and on the viewer's page) and --metrics, driven as a user
would: the page in headless Chromium (tests/browser.py), requests from elsewhere refused, the
metrics file of a run read back (issue 36)."""

from __future__ import annotations

import csv
import http.client
import io
import itertools
import json
import re
import signal
import sys
import tarfile
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from browser import Browser, available
from conftest import requires_rclpy
from procutil import Running, clean_env, mlaunch, run_mlaunch, wait_for

needs_chromium = pytest.mark.skipif(not available(), reason="chromium not installed (apt chromium)")

# ticker: a numbered line every 0.1 s; busy: CPU and no output.
LAUNCH = f"""from launch import LaunchDescription
from launch.actions import ExecuteProcess
TICK = "import time\\ni = 0\\nwhile True:\\n    print('tick', i, flush=True); i += 1; time.sleep(0.1)"
BUSY = "import time\\nwhile True:\\n    sum(range(100000)); time.sleep(0.005)"
def generate_launch_description():
    return LaunchDescription([
        ExecuteProcess(cmd=[{sys.executable!r}, "-c", TICK], name="ticker", output="screen"),
        ExecuteProcess(cmd=[{sys.executable!r}, "-c", BUSY], name="busy", output="screen"),
    ])
"""
OPEN = r"dashboard: open (http://127\.0\.0\.1:(\d+)/launch/)"


class Run:
    """mlaunch running LAUNCH with the panel; ``url`` is the page, ``env`` reaches it by ctl."""

    def __init__(self, tmp_path: Path, *options: str) -> None:
        path = tmp_path / "panel.launch.py"
        path.write_text(LAUNCH)
        self.env = clean_env(ROS_LOG_DIR=str(tmp_path / "logs"))
        self.running = Running(mlaunch(str(path), *options), env=self.env, cwd=str(tmp_path))
        match = self.running.wait_for(OPEN, 30)
        self.url, self.port = match.group(1), int(match.group(2))

    def ctl(self, *words: str) -> dict[str, Any]:
        done = run_mlaunch("ctl", *words, "--json", env=self.env, timeout=30)
        assert done.returncode == 0, done.stdout + done.stderr
        answer: dict[str, Any] = json.loads(done.stdout)
        return answer

    def stop(self) -> None:
        if self.running.proc.poll() is None:
            self.running.signal(signal.SIGINT)
            assert self.running.finish(30) == 130


@pytest.fixture
def run(tmp_path: Path) -> Iterator[Run]:
    launched = Run(tmp_path, "--dashboard")
    try:
        yield launched
    finally:
        try:
            launched.stop()
        finally:
            if launched.running.proc.poll() is None:
                launched.running.kill()


def rows_of(page: Any) -> dict[str, dict[str, str]]:
    rows = page.eval(
        "[...document.querySelectorAll('#procs tbody tr')].map(r => Object.assign({}, r.dataset))"
    )
    return {row["label"]: row for row in rows}


@needs_chromium
@pytest.mark.timeout(120)
def test_the_page_shows_every_process_live_and_restarts_the_one_clicked(
    run: Run, tmp_path: Path
) -> None:
    with Browser(tmp_path / "profile") as browser:
        page = browser.open(run.url)
        # live CPU: the busy process is seen using some, in an update after the first
        page.wait(
            "(() => { const r = document.querySelector('tr[data-label=\"busy-2\"]');"
            " return r && Number(document.body.dataset.updates) > 1 && Number(r.dataset.cpu) > 1 })()",
            30,
            "busy-2's CPU in the table",
        )
        rows = rows_of(page)
        assert set(rows) == {"ticker-1", "busy-2"}
        assert all(row["state"] == "running" for row in rows.values()), rows
        listed = {p["label"]: p for p in run.ctl("list")["processes"]}
        before = int(rows["ticker-1"]["pid"])
        assert before == listed["ticker-1"]["pid"]

        page.click('tr[data-label="ticker-1"] button[data-op="restart"]')
        control = page.wait("document.body.dataset.lastControl", 30, "the restart's answer")
        answer = json.loads(control)
        assert answer["ok"] and answer["op"] == "restart", answer
        assert answer["pid"] not in (0, before), answer
        # the table follows, and ctl (the same control layer) agrees
        page.wait(
            f"document.querySelector('tr[data-label=\"ticker-1\"]').dataset.pid == {answer['pid']}"
            " && document.querySelector('tr[data-label=\"ticker-1\"]').dataset.restarts == 1",
            15,
            "the new pid in the table",
        )
        listed = {p["label"]: p for p in run.ctl("list")["processes"]}
        assert listed["ticker-1"]["pid"] == answer["pid"]
        assert listed["ticker-1"]["restarts"] == 1
        assert listed["busy-2"]["restarts"] == 0
        run.running.wait_for(r"\[ticker-1\]: restart asked by the user \(the launch panel\)", 10)

        page.click('tr[data-label="busy-2"] button[data-op="stop"]')
        page.wait(
            "document.querySelector('tr[data-label=\"busy-2\"]').dataset.state == 'stopped'",
            30,
            "busy-2 stopped",
        )
        assert {p["label"]: p for p in run.ctl("list")["processes"]}["busy-2"]["state"] == "stopped"
        page.click('tr[data-label="busy-2"] button[data-op="start"]')
        page.wait(
            "document.querySelector('tr[data-label=\"busy-2\"]').dataset.state == 'running'",
            30,
            "busy-2 running again",
        )

        # the evidence button: the page asks with its token and hands the browser the archive
        page.click("#evidence")
        got = json.loads(page.wait("document.body.dataset.evidence", 30, "the evidence bundle"))
        assert got["name"].startswith("mlaunch-evidence-") and got["name"].endswith(".tar.gz")
        assert got["size"] > 1000, got


@needs_chromium
@pytest.mark.timeout(120)
def test_the_log_view_follows_new_lines_and_searches(run: Run, tmp_path: Path) -> None:
    with Browser(tmp_path / "profile") as browser:
        page = browser.open(run.url)
        page.wait("!!document.querySelector('tr[data-label=\"ticker-1\"]')", 30, "the table")
        page.click('tr[data-label="ticker-1"] button[data-op="logs"]')

        def last_tick() -> int:
            text = page.eval("document.getElementById('log').textContent")
            ticks = re.findall(r"^tick (\d+)$", text, re.M)
            return int(ticks[-1]) if ticks else -1

        first = wait_for(lambda: last_tick() + 1, 20, "ticks in the log view") - 1
        # lines written after the view opened arrive without a reload
        wait_for(lambda: last_tick() >= first + 10, 20, "the log view to follow")
        lines = page.eval("document.getElementById('log').textContent").splitlines()
        numbers = [int(line.split()[1]) for line in lines if line.startswith("tick ")]
        assert numbers == list(range(numbers[0], numbers[0] + len(numbers))), "lost or repeated"
        page.eval(
            "(() => { const s = document.getElementById('search'); s.value = 'tick 1';"
            " s.dispatchEvent(new Event('input')); })()"
        )
        shown = page.eval("document.getElementById('log').textContent").splitlines()
        assert shown and all(line.startswith("tick 1") for line in shown), shown
        assert page.eval("document.querySelectorAll('#log mark').length") == len(shown)


def request(
    port: int,
    method: str,
    path: str,
    *,
    host: str | None = None,
    origin: str | None = None,
    token: str | None = None,
    body: dict[str, Any] | None = None,
) -> tuple[int, bytes]:
    conn = http.client.HTTPConnection("127.0.0.1", port, timeout=30)
    headers = {"Host": host or f"127.0.0.1:{port}"}
    if origin is not None:
        headers["Origin"] = origin
    if token is not None:
        headers["X-Mlaunch-Token"] = token
    data = None
    if body is not None:
        data = json.dumps(body).encode()
        headers["Content-Type"] = "application/json"
    conn.request(method, path, body=data, headers=headers)
    reply = conn.getresponse()
    status, text = reply.status, reply.read()
    conn.close()
    return status, text


def token_of(port: int) -> str:
    status, page = request(port, "GET", "/launch/")
    assert status == 200
    match = re.search(rb'name="mlaunch-token" content="([^"]+)"', page)
    assert match, page[:300]
    return match.group(1).decode()


def assert_refuses_strangers(port: int, label: str = "ticker-1") -> None:
    """What a page elsewhere, a rebinding name or a request without the token gets."""
    own = f"http://127.0.0.1:{port}"
    token = token_of(port)
    mute = {"op": "mute", "label": label}
    assert request(port, "GET", "/launch/", host="evil.example:80")[0] == 421
    assert request(port, "GET", "/launch/events", host=f"attacker.test:{port}")[0] == 421
    assert request(port, "POST", "/launch/control", origin=own, body=mute)[0] == 403
    status = request(port, "POST", "/launch/control", origin=own, token="x" * 32, body=mute)[0]
    assert status == 403
    foreign = "http://evil.example"
    assert (
        request(port, "POST", "/launch/control", origin=foreign, token=token, body=mute)[0] == 403
    )
    assert request(port, "POST", "/launch/control", token=token, body=mute)[0] == 403  # no Origin
    evil = f"evil.example:{port}"
    rebound = request(
        port, "POST", "/launch/control", host=evil, origin=own, token=token, body=mute
    )
    assert rebound[0] == 421
    # nothing outside the control layer: no file, no command
    assert request(port, "GET", "/launch/../../etc/passwd")[0] == 404
    status, text = request(
        port, "POST", "/launch/control", origin=own, token=token, body={"op": "exec", "label": "ls"}
    )
    assert status == 400 and b"valid" in text
    status, text = request(port, "GET", "/launch/events?follow=../../etc/passwd&lines=5")
    assert status == 404 and b"no process" in text


def test_requests_from_elsewhere_or_without_the_token_are_refused(run: Run) -> None:
    assert_refuses_strangers(run.port)
    listed = {p["label"]: p for p in run.ctl("list")["processes"]}
    assert not listed["ticker-1"]["muted"]
    own = f"http://127.0.0.1:{run.port}"
    status, text = request(
        run.port,
        "POST",
        "/launch/control",
        origin=own,
        token=token_of(run.port),
        body={"op": "mute", "label": "ticker-1"},
    )
    assert status == 200, text
    assert json.loads(text)["process"]["muted"] is True
    said = run.running.wait_for(r"output muted by the user \(the launch panel\)", 10)
    assert run.running.text.count("muted by the user") == 1, said  # the refused ones did not
    assert {p["label"]: p for p in run.ctl("list")["processes"]}["ticker-1"]["muted"]


def download_evidence(port: int) -> dict[str, bytes]:
    """The panel's evidence bundle through ``port``, refused first to all but the page itself
    (it holds every environment); its files by name below the archive's one folder."""
    own = f"http://127.0.0.1:{port}"
    token = token_of(port)
    assert request(port, "POST", "/launch/evidence", origin=own)[0] == 403
    assert request(port, "POST", "/launch/evidence", origin=own, token="x" * 32)[0] == 403
    foreign = request(port, "POST", "/launch/evidence", origin="http://evil.example", token=token)
    assert foreign[0] == 403
    rebound = request(
        port, "POST", "/launch/evidence", host="evil.example:80", origin=own, token=token
    )
    assert rebound[0] == 421
    assert request(port, "GET", "/launch/evidence")[0] == 404

    status, data = request(port, "POST", "/launch/evidence", origin=own, token=token)
    assert status == 200, data[:300]
    files: dict[str, bytes] = {}
    with tarfile.open(fileobj=io.BytesIO(data), mode="r:gz") as tar:
        for member in tar.getmembers():
            assert member.isfile(), member.name
            root, _, name = member.name.partition("/")
            assert root.startswith("mlaunch-evidence-"), member.name
            extracted = tar.extractfile(member)
            assert extracted is not None
            files[name] = extracted.read()
    return files


def test_the_evidence_bundle_of_the_live_run_downloads_from_the_panel(
    run: Run, tmp_path: Path
) -> None:
    run.running.wait_for(r"tick 3\b", 30)
    files = download_evidence(run.port)
    assert "verdict.json" not in files  # a live run has no verdict yet
    assert "logs/launch.log" in files
    plan = json.loads(files["plan.json"])
    records = {r["label"]: r for r in json.loads(files["processes.json"])}
    assert plan["launch_file"].endswith("panel.launch.py")
    listed = {p["label"]: p for p in run.ctl("list")["processes"]}
    assert set(records) == set(listed) and len(records) == 2
    ticker = records["ticker-1"]
    assert ticker["pid"] == listed["ticker-1"]["pid"] and ticker["ended"] is None
    assert ticker["argv"][0] == sys.executable and ticker["environment"]["ROS_LOG_DIR"]
    assert ticker["last_output"] and all(line.startswith("tick ") for line in ticker["last_output"])
    assert b"tick 3\n" in files["logs/ticker-1.log"]
    # the run went on, untouched
    run.running.wait_for(r"tick 20\b", 30)


@pytest.mark.timeout(90)
def test_metrics_file_has_a_row_per_process_per_second_and_a_report(tmp_path: Path) -> None:
    path = tmp_path / "panel.launch.py"
    path.write_text(LAUNCH)
    env = clean_env(ROS_LOG_DIR=str(tmp_path / "logs"))
    metrics = tmp_path / "cost.csv"
    running = Running(mlaunch(str(path), "--metrics", str(metrics)), env=env, cwd=str(tmp_path))
    try:

        def samples() -> int:
            text = metrics.read_text() if metrics.exists() else ""
            return text.count('"busy-2"')

        wait_for(lambda: samples() >= 8, 60, "eight seconds of samples")
        running.signal(signal.SIGINT)
        assert running.finish(30) == 130
    finally:
        if running.proc.poll() is None:
            running.kill()
    with open(metrics, newline="") as f:
        rows = list(csv.DictReader(f))
    assert list(rows[0]) == [
        "time",
        "elapsed",
        "label",
        "pid",
        "state",
        "cpu_percent",
        "rss_bytes",
        "threads",
        "open_files",
    ]
    by_label: dict[str, list[dict[str, str]]] = {}
    for row in rows:
        by_label.setdefault(row["label"], []).append(row)
    assert set(by_label) == {"ticker-1", "busy-2"}
    for label, mine in by_label.items():
        times = [float(r["elapsed"]) for r in mine]
        span = times[-1] - times[0]
        # one row a second: as many intervals as seconds covered (one skipped under load at most)
        assert span - 1.5 < len(mine) - 1 <= span + 0.5, (label, len(mine), span)
        gaps = [b - a for a, b in itertools.pairwise(times)]
        assert all(0.5 < gap < 2.5 for gap in gaps), (label, gaps)
        assert all(int(r["rss_bytes"]) > 1_000_000 for r in mine)
        assert all(int(r["threads"]) >= 1 and int(r["open_files"]) >= 3 for r in mine)
        assert len({r["pid"] for r in mine}) == 1
    busy = [float(r["cpu_percent"]) for r in by_label["busy-2"][1:]]
    assert max(busy) > 5.0, busy
    report = (tmp_path / "cost.html").read_text()
    assert "ticker-1" in report and "busy-2" in report and report.count("<polyline") == 4
    assert "report" in running.text and str(metrics) in running.text


def test_bad_metrics_file_and_dashboard_port_are_clear_errors(tmp_path: Path) -> None:
    path = tmp_path / "panel.launch.py"
    path.write_text(LAUNCH)
    env = clean_env(ROS_LOG_DIR=str(tmp_path / "logs"))
    done = run_mlaunch(str(path), "--metrics", str(tmp_path / "no" / "such.csv"), env=env)
    assert done.returncode == 2
    assert "--metrics" in done.stderr and "such.csv" in done.stderr and "valid" in done.stderr
    done = run_mlaunch(str(path), "--dashboard-port", "99999", env=env)
    assert done.returncode == 2
    assert "--dashboard-port is '99999'" in done.stderr


@needs_chromium
@pytest.mark.timeout(120)
def test_the_page_shows_the_readiness_checks_as_ctl_wait_ready_has_them(
    run: Run, tmp_path: Path
) -> None:
    with Browser(tmp_path / "profile") as browser:
        page = browser.open(run.url)
        page.wait("document.getElementById('ready').dataset.ready == 'true'", 30, "ready")
        checks = page.eval(
            "[...document.querySelectorAll('#checks tr')].map(r => [r.dataset.check,"
            " r.dataset.state, r.cells[1].textContent])"
        )
        done = run_mlaunch("ctl", "wait-ready", "--json", env=run.env, timeout=30)
        assert done.returncode == 0, done.stdout + done.stderr
        answer = json.loads(done.stdout)
        assert checks == [[c["check"], c["state"], c["description"]] for c in answer["checks"]]
        assert [c[2] for c in checks] == [
            "process ticker-1 starts and keeps running",
            "process busy-2 starts and keeps running",
        ]


def test_the_log_ring_numbers_every_line_and_says_what_it_dropped() -> None:
    from mlaunch.parts.dashboard_hub import RING, Hub

    hub = Hub()
    hub.add_output("a", b"".join(b"line %d\n" % i for i in range(10)))
    assert hub.lines_since("a", 0) == (0, [f"line {i}" for i in range(10)], 10)
    assert hub.lines_since("a", 7) == (0, ["line 7", "line 8", "line 9"], 10)
    # a burst longer than the ring: only its last RING lines are kept, numbered on
    hub.add_output("a", b"".join(b"x %d\n" % i for i in range(RING + 5)))
    skipped, lines, end = hub.lines_since("a", 10)
    assert (skipped, len(lines), end) == (5, RING, 10 + RING + 5)
    assert lines[0] == "x 5" and lines[-1] == f"x {RING + 4}"
    hub.add_output("a", b"y\n")
    assert hub.lines_since("a", end) == (0, ["y"], end + 1)
    assert hub.lines_since("a", 0)[0] == end + 1 - RING  # what a late reader missed
    assert hub.lines_since("other", 3) == (0, [], 3)
    assert hub.last["a"] == "y"


@needs_chromium
@pytest.mark.timeout(120)
def test_four_tabs_with_their_log_views_open_all_stay_live(run: Run, tmp_path: Path) -> None:
    # A browser opens at most six connections to one server: a page with a log view holds one
    # stream, not two, so four such tabs (and a fifth page load) all get their updates.
    with Browser(tmp_path / "profile") as browser:
        pages = [browser.open(run.url + "?logs=ticker-1") for _ in range(5)]
        for page in pages:
            page.wait(
                "Number(document.body.dataset.updates) > 1"
                " && Number(document.getElementById('log').dataset.lines) > 5",
                60,
                "a tab's table and log view",
            )


NODE_LAUNCH = """from launch import LaunchDescription
from launch_ros.actions import Node
def generate_launch_description():
    return LaunchDescription([Node(package="demo", executable="talker", name="talker")])
"""


def _loads_rcl(pid: int) -> bool:
    with open(f"/proc/{pid}/maps") as f:
        return "librcl" in f.read()


@requires_rclpy
def test_the_panel_watches_readiness_only_once_a_page_looks(
    tmp_path: Path, ros_env: dict[str, str]
) -> None:
    """The panel comes with every viewer; the readiness checks it shows cost mlaunch a ROS graph
    (rclpy and a dozen threads), so they are watched from the first page on, not before."""
    from procutil import install_package

    prefix = install_package(
        tmp_path / "install",
        "demo",
        {"talker": f"#!{sys.executable}\nimport time\ntime.sleep(600)\n"},
    )
    path = tmp_path / "node.launch.py"
    path.write_text(NODE_LAUNCH)
    metrics = tmp_path / "cost.csv"
    env = clean_env(**ros_env, ROS_LOG_DIR=str(tmp_path / "logs"), AMENT_PREFIX_PATH=str(prefix))
    options = ("--dashboard", "--metrics", str(metrics))
    running = Running(mlaunch(str(path), *options), env=env, cwd=str(tmp_path))
    try:
        port = int(running.wait_for(OPEN, 30).group(2))
        sampled = lambda: metrics.exists() and metrics.read_text().count('"talker-1"') >= 3  # noqa: E731
        wait_for(sampled, 60, "three seconds of the panel's samples")
        assert not _loads_rcl(running.proc.pid)
        connection = http.client.HTTPConnection("127.0.0.1", port, timeout=30)
        connection.request("GET", "/launch/events")
        assert connection.getresponse().status == 200
        wait_for(lambda: _loads_rcl(running.proc.pid), 60, "the readiness watch once a page looks")
        connection.close()
    finally:
        running.kill()
