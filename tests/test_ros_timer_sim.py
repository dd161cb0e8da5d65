"""ROSTimer on simulated time: after SetUseSimTime(True) (before or after the timer) its period
is counted on /clock, as launch_ros's timer on launch's own ROS node; without it, on the wall
clock. A /clock publisher in this process runs simulated time 100 times faster than the wall."""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator
from typing import Any

import pytest
from conftest import requires_rclpy
from test_launch_service import DEADLINE, Screen

from mlaunch.app.launch_service import LaunchService
from mlaunch.launch.actions import LaunchDescription, OpaqueFunction
from mlaunch.launch_ros.actions import SetUseSimTime
from mlaunch.launch_ros.actions.ros_timer import ROSTimer
from mlaunch.parts.ros_clock import SimTimeWaits

pytestmark = requires_rclpy

STEP = 10  # simulated seconds per publication
EVERY = 0.1  # wall seconds between publications


class SimClock:
    """Publishes /clock from 0, STEP simulated seconds every EVERY wall seconds."""

    def __init__(self) -> None:
        from rclpy.context import Context
        from rclpy.node import Node
        from rosgraph_msgs.msg import Clock

        self.context = Context()
        self.context.init([])
        self.node = Node("_test_sim_clock", context=self.context)
        self.publisher = self.node.create_publisher(Clock, "/clock", 10)
        self.Clock = Clock
        self.sent = -STEP
        self.stopping = threading.Event()
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _run(self) -> None:
        while not self.stopping.wait(EVERY):
            self.sent += STEP
            message = self.Clock()
            message.clock.sec = self.sent
            self.publisher.publish(message)

    def close(self) -> None:
        self.stopping.set()
        self.thread.join(5)
        self.node.destroy_node()
        self.context.try_shutdown()


@pytest.fixture
def sim_clock(ros_env: dict[str, str]) -> Iterator[SimClock]:
    clock = SimClock()
    try:
        yield clock
    finally:
        clock.close()


def timed_launch(sim_time_first: bool | None, period: float) -> tuple[LaunchService, list[Any]]:
    """A service whose ROSTimer records (wall time, /clock sent) when it fires; SetUseSimTime
    before the timer, after it, or (None) not at all."""
    fired: list[Any] = []
    timer = ROSTimer(
        period=period, actions=[OpaqueFunction(function=lambda context: fired.append(1))]
    )
    entities: list[Any] = [timer]
    if sim_time_first is not None:
        entities.insert(0 if sim_time_first else 1, SetUseSimTime(True))
    service = LaunchService(screen=Screen())
    service.include_launch_description(LaunchDescription(entities))
    return service, fired


@pytest.mark.parametrize("sim_time_first", [True, False], ids=["set-before", "set-after"])
def test_a_ros_timer_on_sim_time_follows_clock(sim_clock: SimClock, sim_time_first: bool) -> None:
    # 300 simulated seconds: 3 s of wall time at the clock's pace, 5 minutes on the wall.
    service, fired = timed_launch(sim_time_first, 300.0)
    started = time.monotonic()
    assert service.run() == 0
    took = time.monotonic() - started
    assert fired == [1]
    assert sim_clock.sent >= 300
    assert took < DEADLINE


def test_without_sim_time_a_ros_timer_counts_wall_time() -> None:
    service, fired = timed_launch(None, 0.2)
    started = time.monotonic()
    assert service.run() == 0
    assert fired == [1]
    assert time.monotonic() - started >= 0.2


def test_a_waiting_sim_time_timer_is_cancelled_by_shutdown(
    ros_env: dict[str, str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Nothing publishes /clock: the timer waits, keeps the launch running, and shutdown()
    ends it without running its actions."""
    # The part's thread ends once its graph is up: ~20 ms when an earlier test of this process
    # imported rclpy (under xdist, a polling check missed it). Its start is noted instead.
    graph_started = threading.Event()
    start_graph = SimTimeWaits._start_graph

    def noted(part: SimTimeWaits) -> None:
        graph_started.set()
        start_graph(part)

    monkeypatch.setattr(SimTimeWaits, "_start_graph", noted)
    service, fired = timed_launch(True, 5.0)
    thread = service.run_in_thread()
    # The wait was handed to the ROS clock part, and keeps the otherwise idle launch running.
    assert graph_started.wait(DEADLINE)
    assert thread.is_alive()
    service.shutdown()
    thread.join(DEADLINE)
    assert not thread.is_alive()
    assert (service.return_code, fired) == (0, [])
