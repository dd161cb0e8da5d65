"""``launch_testing_ros.WaitForTopics``: wait for messages on topics from a launch test.

    with launch_testing_ros.WaitForTopics([("chatter", String)], timeout=10) as wait:
        wait.received_messages("chatter")

rclpy is imported when a WaitForTopics is made, never before (the ``ros`` extra provides it).
"""

from __future__ import annotations

import os
import threading
from collections import deque

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Iterable
    from typing import Any


class WaitForTopics:
    """Subscribes to ``(topic, message type)`` pairs on a private node and rclpy context.

    ``wait()`` is True once every topic got a message within ``timeout`` seconds; as a context
    manager it raises RuntimeError naming the topics that got none, and shuts down at exit.
    The last ``messages_received_buffer_length`` messages of each topic are kept.
    """

    def __init__(
        self,
        topic_tuples: Iterable[tuple[str, Any]],
        timeout: float = 5.0,
        messages_received_buffer_length: int = 10,
    ) -> None:
        import rclpy
        from rclpy.context import Context
        from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor

        self.topic_tuples = list(topic_tuples)
        self.timeout = timeout
        self._length = messages_received_buffer_length
        self._context = Context()
        rclpy.init(context=self._context)
        self._executor = SingleThreadedExecutor(context=self._context)
        self._node = rclpy.create_node(
            f"_mlaunch_wait_{os.urandom(5).hex()}", context=self._context
        )
        self._executor.add_node(self._node)
        self._lock = threading.Lock()
        self._all_received = threading.Event()
        self._expected: set[str] = set()
        self._received: set[str] = set()
        self._messages: dict[str, deque[Any]] = {}
        self._subscriptions: dict[tuple[str, Any], Any] = {}

        def spin() -> None:
            try:
                self._executor.spin()
            except ExternalShutdownException:
                pass  # shutdown() ended the context: the normal way out

        self._spinner = threading.Thread(target=spin, name="WaitForTopics", daemon=True)
        self._spinner.start()

    def wait(self) -> bool:
        """Subscribe (again), forget what came before, and wait for a message on every topic."""
        with self._lock:
            self._all_received.clear()
            self._received = set()
            for buffer in self._messages.values():
                buffer.clear()
            for topic, message_type in self.topic_tuples:
                if (topic, message_type) in self._subscriptions:
                    continue
                self._expected.add(topic)
                self._messages[topic] = deque(maxlen=self._length)
                self._subscriptions[(topic, message_type)] = self._node.create_subscription(
                    message_type, topic, self._on_message(topic), 10
                )
        return self._all_received.wait(self.timeout)

    def _on_message(self, topic: str) -> Any:
        def received(message: Any) -> None:
            with self._lock:
                self._messages[topic].append(message)
                self._received.add(topic)
                if self._received == self._expected:
                    self._all_received.set()

        return received

    def shutdown(self) -> None:
        self._context.try_shutdown()
        self._spinner.join()
        self._node.destroy_node()

    def topics_received(self) -> set[str]:
        with self._lock:
            return set(self._received)

    def topics_not_received(self) -> set[str]:
        with self._lock:
            return self._expected - self._received

    def received_messages(self, topic_name: str) -> list[Any]:
        with self._lock:
            if topic_name not in self._messages:
                raise KeyError(f"No messages received for topic: {topic_name}")
            return list(self._messages[topic_name])

    def __enter__(self) -> WaitForTopics:
        if not self.wait():
            missing = self.topics_not_received()
            self.shutdown()
            raise RuntimeError(f"Did not receive messages on these topics: {missing}")
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.shutdown()


__all__ = ["WaitForTopics"]
