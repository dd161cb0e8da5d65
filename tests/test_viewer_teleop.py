"""The viewer's teleop stops: a held key drives at 12.5 Hz, a release, a lost focus, a hidden or
left page send a stop, and the server stops a motion no command renewed for 0.5 s (a closed tab,
a lost connection); the page says so. In headless Chromium as a user would drive, and against the
server directly. Also: the depth picture has a column of its own, left of the map."""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from browser import Browser, Page, available
from procutil import wait_for

from mlaunch.standins.viewer import DisplayConfig, PageServer, ViewerState, serve
from mlaunch.standins.viewer_http import DEADMAN, DeadMan

STOP = (0.0, 0.0)


class Commands:
    """What the page's keys made the server publish, in order, with when."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.seen: list[tuple[float, float, float]] = []

    def __call__(self, linear: float, angular: float) -> None:
        with self.lock:
            self.seen.append((time.monotonic(), linear, angular))

    def twists(self) -> list[tuple[float, float]]:
        with self.lock:
            return [(v, w) for _, v, w in self.seen]


@pytest.fixture
def driven() -> Iterator[tuple[PageServer, ViewerState, Commands]]:
    commands = Commands()
    state = ViewerState(DisplayConfig(depth_topic="/cam/depth"))
    server = serve(state, 0, time.monotonic, commands)
    yield server, state, commands
    server.shutdown()
    server.server_close()


def test_the_dead_man_stops_a_motion_no_command_renews() -> None:
    now = [100.0]
    sent: list[tuple[float, float]] = []
    deadman = DeadMan(lambda v, w: sent.append((v, w)), lambda: now[0])
    deadman(0.5, 0.0)
    now[0] += DEADMAN - 0.01
    assert not deadman.check()  # renewed in time: still driving
    deadman(0.5, 0.0)
    now[0] += DEADMAN - 0.01
    assert not deadman.check()
    now[0] += 0.02
    assert deadman.check()  # 0.5 s without a command: stopped, once
    now[0] += 5
    assert not deadman.check()
    deadman(0.0, 0.0)  # a stop needs no dead-man
    now[0] += 5
    assert not deadman.check()
    assert sent == [(0.5, 0.0), (0.5, 0.0), STOP, STOP]


def test_the_server_stops_a_page_that_went_silent(
    driven: tuple[PageServer, ViewerState, Commands],
) -> None:
    """A page that sent a motion and then nothing (its tab closed mid-drive)."""
    import urllib.request

    server, _, commands = driven
    url = f"http://127.0.0.1:{server.server_address[1]}"
    request = urllib.request.Request(
        f"{url}/cmd_vel",
        data=b'{"linear": 0.5, "angular": 0}',
        headers={"Content-Type": "application/json", "Origin": url},
    )
    with urllib.request.urlopen(request, timeout=10) as reply:
        assert reply.status == 204
    wait_for(lambda: commands.twists()[-1] == STOP or None, 10, "the dead-man's stop")
    sent, stopped = commands.seen[0][0], commands.seen[-1][0]
    assert stopped - sent >= DEADMAN
    assert commands.twists() == [(0.5, 0.0), STOP]


def _key(page: Page, kind: str, key: str = "ArrowUp", code: int = 38) -> None:
    page.send(
        "Input.dispatchKeyEvent",
        {"type": kind, "key": key, "code": key, "windowsVirtualKeyCode": code},
    )


def _hold(page: Page, commands: Commands) -> int:
    """Press the up arrow and wait until the page repeats its command; how many were seen."""
    before = len(commands.twists())
    _key(page, "keyDown")
    wait_for(
        lambda: commands.twists()[before:].count((0.5, 0.0)) >= 3 or None,
        20,
        "a held key's command, repeated",
    )
    return len(commands.twists())


@pytest.mark.skipif(not available(), reason="chromium not installed (apt chromium)")
def test_a_held_key_repeats_and_every_way_of_leaving_stops(
    driven: tuple[PageServer, ViewerState, Commands], tmp_path: Path
) -> None:
    server, _, commands = driven
    url = f"http://127.0.0.1:{server.server_address[1]}/"
    with Browser(tmp_path / "profile") as browser:
        page = browser.open(url)
        page.wait("document.readyState === 'complete'", 20, "the page")
        assert page.eval("DRIVE_PERIOD_MS") <= 100  # at least 10 Hz while held
        said = page.eval("document.getElementById('drive-safety').textContent")
        assert "loses focus or is hidden" in said and "0.5 s" in said, said

        for leave in (
            lambda: _key(page, "keyUp"),
            lambda: page.eval("window.dispatchEvent(new Event('blur'))"),
            lambda: page.eval(
                "Object.defineProperty(document, 'hidden', {value: true, configurable: true});"
                " document.dispatchEvent(new Event('visibilitychange'))"
            ),
            lambda: page.eval("window.dispatchEvent(new Event('pagehide'))"),
        ):
            page.eval(
                "Object.defineProperty(document, 'hidden', {value: false, configurable: true})"
            )
            _hold(page, commands)
            leave()
            wait_for(lambda: commands.twists()[-1] == STOP or None, 10, "the page's stop")
            page.wait("driving === null && held.size === 0", 10, "the page no longer sending")
            _key(page, "keyUp")  # (the key itself, for the next round)
            wait_for(lambda: commands.twists()[-1] == STOP or None, 10, "the release's stop")


@pytest.mark.skipif(not available(), reason="chromium not installed (apt chromium)")
def test_the_depth_picture_covers_none_of_the_map(
    driven: tuple[PageServer, ViewerState, Commands], tmp_path: Path
) -> None:
    """At 1280x800 the depth panel sat over the map's lower left corner."""
    import numpy as np

    server, state, _ = driven
    depth = np.full((48, 64), 2.0, dtype="<f4")
    state.set_depth(64, 48, "32FC1", depth.tobytes(), 4.0, now=time.monotonic())
    url = f"http://127.0.0.1:{server.server_address[1]}/"
    with Browser(tmp_path / "profile", width=1280, height=800) as browser:
        page = browser.open(url)
        page.wait("document.body.classList.contains('with-depth')", 20, "the depth panel")
        panel = page.eval("JSON.stringify(el('depth-panel').getBoundingClientRect())")
        canvas = page.eval("JSON.stringify(el('view').getBoundingClientRect())")
    import json

    panel_box, map_box = json.loads(panel), json.loads(canvas)
    assert panel_box["width"] > 0 and panel_box["right"] <= map_box["left"], (panel_box, map_box)
    assert map_box["right"] == 1280 or map_box["width"] > 900, map_box
