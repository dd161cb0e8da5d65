"""What every stand-in program shares: the stop flag and the node's run-until-shutdown tail.

Nothing here imports rclpy at module level; ``spin_until_shutdown`` imports it when called.
"""

from __future__ import annotations

import signal
import sys
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


def latched(depth: int = 1) -> Any:
    """The QoS of a latched topic: reliable and transient local, so late joiners get the last
    ``depth`` messages (rclpy imported here)."""
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

    return QoSProfile(
        depth=depth,
        reliability=ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.TRANSIENT_LOCAL,
    )


def install_stop_flag() -> StopFlag:
    stop = StopFlag()
    signal.signal(signal.SIGINT, stop)
    signal.signal(signal.SIGTERM, stop)
    return stop


def init_ros(args: list[str], node_name: str) -> StopFlag | None:
    """rclpy.init with our own SIGINT/SIGTERM handling; None (after one error line) on bad args.

    rclpy's own handler shuts the context down from inside the signal handler, which races
    with a subscription being taken: a Ctrl-C at the wrong moment ended a node with a pybind11
    RuntimeError traceback. With rclpy's handlers off, the signal only sets a flag and the spin
    loop ends cleanly.
    """
    import rclpy
    from rclpy.signals import SignalHandlerOptions

    stop = install_stop_flag()
    try:
        rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.NO)
    except Exception as exc:  # rcl reports bad --ros-args as a generic RCLError
        print(f"[ERROR] [{node_name}]: invalid ROS arguments: {exc}", file=sys.stderr)
        return None
    return stop


def spin(node: Any, stop: StopFlag) -> None:
    """Run the node's callbacks until the stop flag is set or ROS shuts down."""
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.utilities import ok

    executor = SingleThreadedExecutor(context=node.context)
    executor.add_node(node)
    try:
        while not stop.requested and ok(context=node.context):
            executor.spin_once(timeout_sec=0.1)
    finally:
        executor.remove_node(node)


def spin_until_shutdown(
    node: Any,
    start: Callable[[], object],
    input_errors: dict[type[Exception], str],
    stop: StopFlag,
) -> int:
    """``start()`` then spin until Ctrl-C or shutdown; unusable input is one logged line, exit 1.

    ``input_errors`` maps the program's own exception types for a bad URDF or parameter to the
    prefix of their line: their message is the whole story, so no traceback.
    """
    from rclpy.executors import ExternalShutdownException
    from rclpy.utilities import try_shutdown

    try:
        start()
        spin(node, stop)
    except tuple(input_errors) as exc:
        prefix = next(p for kind, p in input_errors.items() if isinstance(exc, kind))
        node.get_logger().error(f"{prefix}{exc}")
        return EXIT_FAILURE
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        try_shutdown()
    return EXIT_OK
