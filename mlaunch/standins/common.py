"""What every stand-in program shares: the stop flag and the node's run-until-shutdown tail.

Nothing here imports rclpy at module level; ``spin_until_shutdown`` imports it when called.
"""

from __future__ import annotations

import signal
from collections.abc import Callable
from types import FrameType
from typing import Any

EXIT_OK = 0
EXIT_FAILURE = 1


class StopFlag:
    """Set by SIGINT/SIGTERM; the program's own loop checks it (handlers only record)."""

    def __init__(self) -> None:
        self.requested = False

    def __call__(self, signum: int, frame: FrameType | None) -> None:
        self.requested = True


def install_stop_flag() -> StopFlag:
    stop = StopFlag()
    signal.signal(signal.SIGINT, stop)
    signal.signal(signal.SIGTERM, stop)
    return stop


def spin_until_shutdown(
    node: Any, start: Callable[[], object], input_errors: dict[type[Exception], str]
) -> int:
    """``start()`` then spin until Ctrl-C or shutdown; unusable input is one logged line, exit 1.

    ``input_errors`` maps the program's own exception types for a bad URDF or parameter to the
    prefix of their line: their message is the whole story, so no traceback.
    """
    import rclpy
    from rclpy.executors import ExternalShutdownException

    try:
        start()
        rclpy.spin(node)
    except tuple(input_errors) as exc:
        prefix = next(p for kind, p in input_errors.items() if isinstance(exc, kind))
        node.get_logger().error(f"{prefix}{exc}")
        return EXIT_FAILURE
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
    return EXIT_OK
