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

# The longest a signal waits to be noticed while the executor sleeps in rcl_wait.
SPIN_PERIOD = 0.1


class StopNode(Exception):
    """Raised from a callback to end the program with `code` after a clean shutdown."""

    def __init__(self, code: int) -> None:
        super().__init__(code)
        self.code = code


class _Signals:
    """Our own SIGINT/SIGTERM handling; rclpy's handlers are not installed at all.

    Before rclpy.init the handler raises KeyboardInterrupt: nothing ROS exists yet, so
    abandoning the start-up is clean. Afterwards it only records the signal and the spin loop,
    which wakes at least every SPIN_PERIOD, ends. Why not rclpy's handlers: an exception raised
    at an arbitrary bytecode inside rclpy leaves half-built objects (an Executor whose __del__
    prints an "Exception ignored" traceback), and relying on rclpy's handler to shut the
    context down lost about one signal in 40 that landed just before spin() (measured).
    """

    def __init__(self) -> None:
        self.rclpy_ready = False
        self.received = False

    def __call__(self, signum: int, frame: object) -> None:
        self.received = True
        if not self.rclpy_ready:
            raise KeyboardInterrupt

    def install(self) -> None:
        # A parent may have left SIGINT ignored (background jobs of a non-interactive shell),
        # and SIGTERM's default would end us with -15 instead of 0 during `import rclpy`.
        signal.signal(signal.SIGINT, self)
        signal.signal(signal.SIGTERM, self)


def split_args(parser: argparse.ArgumentParser, argv: list[str]) -> argparse.Namespace:
    """Parse the non-ROS part of argv (everything outside `--ros-args ... --`)."""
    from rclpy.utilities import remove_ros_args

    return parser.parse_args(remove_ros_args(argv)[1:])


def run(build: Callable[[list[str]], Any], argv: list[str] | None = None) -> int:
    """Init rclpy with argv, make the node with `build(argv)`, spin it; return the exit status."""
    argv = list(sys.argv if argv is None else argv)
    signals = _Signals()
    signals.install()
    try:
        return _spin(build, argv, signals)
    except KeyboardInterrupt:
        return 0  # a signal before rclpy was up: still a clean stop


def _spin(build: Callable[[list[str]], Any], argv: list[str], signals: _Signals) -> int:
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.signals import SignalHandlerOptions

    rclpy.init(args=argv, signal_handler_options=SignalHandlerOptions.NO)
    signals.rclpy_ready = True
    node = None
    try:
        node = build(argv)
        executor = SingleThreadedExecutor()
        executor.add_node(node)
        while not signals.received:
            executor.spin_once(timeout_sec=SPIN_PERIOD)
        return 0
    except StopNode as stop:
        return stop.code
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()


def main(build: Callable[[list[str]], Any]) -> None:
    """Entry point for a program: run it and exit with its status."""
    sys.exit(run(build))
