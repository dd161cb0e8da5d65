"""Shared fixtures: a private ROS domain per test, the rclpy availability check, and the lock
that lets a test marked ``serial`` run alone under pytest-xdist."""

from __future__ import annotations

import importlib.util
import os
import signal
import sys
from collections.abc import Generator, Iterator
from pathlib import Path

import alone
import pytest
from ros_domain import claim as claim_domain

from mlaunch import compat

# The suite loads launch files through mlaunch's library as the applications do: with the ROS 2
# module names served (mlaunch.compat), which each application installs before loading.
compat.install()

REPO = Path(__file__).resolve().parent.parent

# The venv's own ament prefix holds the real ROS 2 nodes when setup built them (--real-nodes);
# an activated venv puts it on AMENT_PREFIX_PATH. The suite decides per test which programs run:
# the stand-in tests must not get the real ones because of the shell they were started from
# (test_real_nodes adds the prefix back where it wants the real programs).
VENV_PREFIX = os.path.realpath(sys.prefix)
_kept = [
    entry
    for entry in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep)
    if entry and os.path.realpath(entry) != VENV_PREFIX
]
if "AMENT_PREFIX_PATH" in os.environ:
    os.environ["AMENT_PREFIX_PATH"] = os.pathsep.join(_kept)

# A shell without job control starts `cmd &` with SIGINT ignored (POSIX), and an ignored signal
# stays ignored in every child: a suite started so from a script would give the launchers its
# tests stop with Ctrl-C's SIGINT (ros2 launch, roslaunch, the stand-ins) no way to hear it, and
# each of those runs would wait out its stop deadline before the SIGKILL (14 reference recordings
# took 44 s each instead of 8). The children must see a terminal's default.
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)

HAVE_RCLPY = importlib.util.find_spec("rclpy") is not None
requires_rclpy = pytest.mark.skipif(
    not HAVE_RCLPY, reason="rclpy is not installed: pip install -e '.[ros]' to run the ROS tests"
)


@pytest.hookimpl(wrapper=True, tryfirst=True)
def pytest_runtest_protocol(
    item: pytest.Item, nextitem: pytest.Item | None
) -> Generator[None, object, object]:
    """Under pytest-xdist, a test marked ``serial`` runs alone (tests/alone.py says why)."""
    folder = alone.lock_folder(item.config)
    if folder is None:
        return (yield)
    serial = _serial(item)
    with alone.turn(folder, serial, keep=serial and nextitem is not None and _serial(nextitem)):
        return (yield)


def _serial(item: pytest.Item) -> bool:
    return item.get_closest_marker(alone.MARKER) is not None


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """The serial tests first, one after the other (tests/alone.py: they drain the run once)."""
    items.sort(key=lambda item: not _serial(item))  # a stable sort: the rest keep their order


@pytest.fixture
def ros_env(monkeypatch: pytest.MonkeyPatch) -> Iterator[dict[str, str]]:
    """A private ROS domain on localhost, set in os.environ for this test and returned as a dict.

    Children inherit it, so every node a test starts lives in this domain only.
    """
    domain, fd = claim_domain()
    values = {
        "ROS_DOMAIN_ID": str(domain),
        "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST",
        "RMW_IMPLEMENTATION": "rmw_fastrtps_cpp",
    }
    # ROS_LOCALHOST_ONLY is deprecated in Jazzy (the range above replaces it) and only makes
    # every node print a warning.
    monkeypatch.delenv("ROS_LOCALHOST_ONLY", raising=False)
    for key, value in values.items():
        monkeypatch.setenv(key, value)
    try:
        yield dict(os.environ)
    finally:
        os.close(fd)
