"""``DataRepublisher``: republish the messages of a topic on another, transformed."""

from __future__ import annotations

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable
    from typing import Any


class DataRepublisher:
    """Subscribes to ``listen_topic`` on ``node`` and publishes ``transform_fn(message)`` on
    ``publish_topic`` (both of ``msg_type``); a falsy result drops the message."""

    def __init__(
        self,
        node: Any,
        listen_topic: str,
        publish_topic: str,
        msg_type: Any,
        transform_fn: Callable[[Any], Any],
    ) -> None:
        self.__num_received = 0
        self.__republished_list: list[Any] = []
        self.__node = node
        self.__transform_fn = transform_fn
        self.__subscriber = node.create_subscription(msg_type, listen_topic, self.__received, 10)
        self.__publisher = node.create_publisher(msg_type, publish_topic, 10)

    def shutdown(self) -> None:
        """Stop republishing: the subscription and the publisher go."""
        self.__node.destroy_subscription(self.__subscriber)
        self.__node.destroy_publisher(self.__publisher)

    def get_num_received(self) -> int:
        return self.__num_received

    def get_num_republished(self) -> int:
        """How many messages were republished (fewer than received when some were dropped)."""
        return len(self.__republished_list)

    def get_republished(self) -> list[Any]:
        """The received messages that were republished (transformed), in order.

        As launch_testing_ros keeps them: the message as received, not the transformed one.
        """
        return self.__republished_list

    def __received(self, message: Any) -> None:
        self.__num_received += 1
        transformed = self.__transform_fn(message)
        if transformed:
            self.__republished_list.append(message)
            self.__publisher.publish(transformed)


__all__ = ["DataRepublisher"]
