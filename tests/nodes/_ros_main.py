"""Shared main loop of the test node programs: init rclpy, spin one node, exit cleanly.

Every program here must behave like a well-mannered ROS 2 node under a supervisor: SIGINT or
SIGTERM ends it with status 0 and no traceback, whenever the signal arrives (even during
`import rclpy`), and a program may end itself with a chosen status by raising `StopNode`.
"""

from __future__ import annotations

import argparse
import signal
import sys
from collections.abc import Callable
from typing import Any


class StopNode(Exception):
    """Raised from a callback to end the program with `code` after a clean shutdown."""

    def __init__(self, code: int) -> None:
        super().__init__(code)
        self.code = code


def split_args(parser: argparse.ArgumentParser, argv: list[str]) -> argparse.Namespace:
    """Parse the non-ROS part of argv (everything outside `--ros-args ... --`)."""
    from rclpy.utilities import remove_ros_args

    return parser.parse_args(remove_ros_args(argv)[1:])


def _interrupt(signum: int, frame: object) -> None:
    raise KeyboardInterrupt


def run(build: Callable[[list[str]], Any], argv: list[str] | None = None) -> int:
    """Init rclpy with argv, make the node with `build(argv)`, spin it; return the exit status."""
    argv = list(sys.argv if argv is None else argv)
    # Before rclpy installs its own handlers (which chain to these): a parent may have left
    # SIGINT ignored (background jobs of a non-interactive shell), and SIGTERM's default would
    # kill us with -15 instead of a clean 0 if it came during `import rclpy`.
    signal.signal(signal.SIGINT, _interrupt)
    signal.signal(signal.SIGTERM, _interrupt)
    try:
        return _spin(build, argv)
    except KeyboardInterrupt:
        # SIGINT before rclpy installed its handler (or during import): still a clean stop.
        return 0


def _spin(build: Callable[[list[str]], Any], argv: list[str]) -> int:
    import rclpy
    from rclpy.executors import ExternalShutdownException

    rclpy.init(args=argv)
    node = None
    code = 0
    try:
        node = build(argv)
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        code = 0
    except StopNode as stop:
        code = stop.code
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
    return code


def main(build: Callable[[list[str]], Any]) -> None:
    """Entry point for a program: run it and exit with its status."""
    sys.exit(run(build))
