"""The rate figures of ``mlaunch test``'s table rest on enough data (issue 27, item 18): a
30 Hz topic passed on 0.3 s of messages. Judged here on real TopicWatch records."""

from __future__ import annotations

import time
from typing import Any

from mlaunch.parts.graph_types import TopicWatch
from mlaunch.smoke.expectations import parse_target
from mlaunch.smoke.watch import MIN_RATE_SPAN, GraphProbe


class Graph:
    """A ROS graph with one topic whose watch has the arrivals a test gives it."""

    def __init__(self, arrivals: list[float]) -> None:
        self.watch = TopicWatch("/scan", "sensor_msgs/msg/LaserScan")
        now = time.monotonic()
        for at in sorted(arrivals, reverse=True):  # seconds before now, oldest first
            self.watch._stamps.append(now - at)
        self.watch.count = len(arrivals)
        if arrivals:
            self.watch.first_at, self.watch.last_at = now - max(arrivals), now - min(arrivals)

    def watch_topic(self, topic: str) -> TopicWatch:
        return self.watch

    def node_names(self) -> set[str]:
        return set()

    def topic_types(self) -> dict[str, list[str]]:
        return {"/scan": ["sensor_msgs/msg/LaserScan"]}


def _judge(arrivals: list[float], spec: str = "/scan:30") -> tuple[bool, str]:
    graph: Any = Graph(arrivals)
    expectation = parse_target("topic", spec, "test")
    ((_, met, seen),) = GraphProbe(graph).check([expectation])
    return met, seen


def test_a_rate_from_a_fraction_of_a_second_is_too_little_data() -> None:
    met, seen = _judge([i / 30 for i in range(10)])  # 10 messages at 30 Hz: 0.3 s
    assert not met
    assert seen == (
        f"too little data: 10 messages over 0.3 s; a rate needs 10 over {MIN_RATE_SPAN:g} s or"
        " more (wanted >= 27.0 Hz)"
    )


def test_a_rate_over_enough_time_is_judged_and_says_what_it_rests_on() -> None:
    met, seen = _judge([i / 30 for i in range(40)])  # 40 messages: 1.3 s
    assert met and seen == "30.0 Hz over 1.3 s (40 messages)", seen
    met, seen = _judge([i / 3 for i in range(12)], "/scan:10")  # 3 Hz for 3.7 s
    assert not met and seen.startswith("too slow: 3.0 Hz over 1.7 s (6 messages)"), seen
