"""The last seconds of named topics while ``mlaunch test`` runs, written as MCAP on a failure.

A ring buffer in memory: the smoke run's own graph node (mlaunch.parts.bridge.RosGraph.record:
no second DDS participant) subscribes to each topic raw (the CDR bytes as they came, nothing
decoded) once it has a publisher; the ring keeps what arrived in the last ``seconds`` (and at
most MAX_BYTES), and ``write`` puts it in an MCAP file with each type's
``ros2msg`` schema (mlaunch.ros.msgdef) and ``cdr`` channels: what ``ros2 bag`` and Foxglove read.
It is made only for a test run that names topics, so neither rclpy nor the ``mcap`` library is
on a plain run's path.
"""

from __future__ import annotations

import threading
import time
from collections import deque
from collections.abc import Iterable, Mapping
from typing import Any

# The ring's cap, whatever the window: a camera at 30 Hz must not eat the machine.
MAX_BYTES = 256 * 1024 * 1024


class Recorder:
    """Keeps the last ``seconds`` of ``topics``; the smoke run's graph feeds it (``keep``)."""

    def __init__(self, topics: Iterable[str], seconds: float) -> None:
        self.seconds = seconds
        self.topics = sorted(set(topics))
        self.ring: deque[tuple[str, int, bytes]] = deque()
        self.bytes = 0
        self.received = 0  # messages, all told (the ring keeps the last ``seconds``)
        self.types: dict[str, str] = {}  # topic -> its message type
        self.lock = threading.Lock()

    def attach(self, graph: Any) -> None:
        """Subscribe (raw) to each topic on ``graph`` (a mlaunch.parts.bridge.RosGraph)."""
        for topic in self.topics:
            graph.record(topic, self.keep)

    def keep(self, topic: str, type_name: str, data: bytes) -> None:
        """One message as it came (on the graph's thread)."""
        now = time.time_ns()
        oldest = now - int(self.seconds * 1e9)
        with self.lock:
            self.types.setdefault(topic, type_name)
            self.ring.append((topic, now, data))
            self.bytes += len(data)
            self.received += 1
            while self.ring and (self.ring[0][1] < oldest or self.bytes > MAX_BYTES):
                self.bytes -= len(self.ring.popleft()[2])

    def snapshot(self) -> list[tuple[str, int, bytes]]:
        with self.lock:
            return list(self.ring)

    def write(self, path: str, environ: Mapping[str, str] | None = None) -> tuple[int, int]:
        """The ring as an MCAP file at ``path``: (messages, topics) written."""
        from mcap.writer import Writer

        from mlaunch.ros.msgdef import MessageDefinitionError, definition

        messages = self.snapshot()
        channels: dict[str, int] = {}
        with open(path, "wb") as f:
            writer = Writer(f)
            writer.start(profile="ros2", library="mlaunch")
            for topic, type_name in sorted(self.types.items()):
                try:
                    schema_text = definition(type_name, environ)
                except MessageDefinitionError:
                    schema_text = ""  # the bytes are kept; a reader needs the type's package
                schema = writer.register_schema(type_name, "ros2msg", schema_text.encode())
                channels[topic] = writer.register_channel(topic, "cdr", schema)
            sequence = 0
            for topic, stamp, data in messages:
                channel = channels.get(topic)
                if channel is None:
                    continue
                writer.add_message(channel, stamp, data, stamp, sequence)
                sequence += 1
            writer.finish()  # type: ignore[no-untyped-call]
        return sequence, len(channels)
