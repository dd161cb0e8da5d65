"""Shared fixtures: a private ROS domain per test, and the rclpy availability check."""

from __future__ import annotations

import fcntl
import importlib.util
import os
import random
from collections.abc import Iterator
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent

HAVE_RCLPY = importlib.util.find_spec("rclpy") is not None
requires_rclpy = pytest.mark.skipif(
    not HAVE_RCLPY, reason="rclpy is not installed: pip install -e '.[ros]' to run the ROS tests"
)


def _claim_domain() -> tuple[int, int]:
    """Take a ROS_DOMAIN_ID no other test run on this machine holds, by a lock file per id.

    The lock is held until the fd is closed, so overlapping pytest runs (two developers, CI and
    a benchmark) never share a DDS domain and never see each other's nodes.
    """
    ids = list(range(101, 200))
    random.shuffle(ids)
    for domain in ids:
        fd = os.open(f"/tmp/mlaunch-ros-domain-{domain}.lock", os.O_CREAT | os.O_RDWR, 0o666)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            os.close(fd)
            continue
        return domain, fd
    raise RuntimeError("no free ROS_DOMAIN_ID in 101..199")


@pytest.fixture
def ros_env(monkeypatch: pytest.MonkeyPatch) -> Iterator[dict[str, str]]:
    """A private ROS domain on localhost, set in os.environ for this test and returned as a dict.

    Children inherit it, so every node a test starts lives in this domain only.
    """
    domain, fd = _claim_domain()
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
