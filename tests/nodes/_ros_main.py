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

    The handler only records the signal; the program looks at it where stopping is clean: after
    ``import rclpy``, after ``rclpy.init`` and in the spin loop, which wakes at least every
    SPIN_PERIOD. It raises nothing: a KeyboardInterrupt raised at an arbitrary bytecode inside
    rclpy (its import, ``rclpy.init`` returning with the middleware's participant made) leaves
    half-built objects and a context never shut down, whose teardown at exit is native code.
    Why not rclpy's handlers: relying on them to shut the context down lost about one signal
    in 40 that landed just before spin() (measured).

    A recorded signal is only acted on when Python runs, and Python runs no handler while the
    main thread is in native code (rcl, the middleware's teardown): there a SIGTERM after the
    SIGINT was ignored as well and the supervisor needed SIGKILL. So after the first signal
    both get their default action back: the supervisor's next step ends the program at once.
    """

    def __init__(self) -> None:
        self.received = False

    def __call__(self, signum: int, frame: object) -> None:
        self.received = True
        signal.signal(signal.SIGINT, signal.SIG_DFL)
        signal.signal(signal.SIGTERM, signal.SIG_DFL)

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
    return _spin(build, argv, signals)


def _spin(build: Callable[[list[str]], Any], argv: list[str], signals: _Signals) -> int:
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.signals import SignalHandlerOptions

    if signals.received:
        return 0  # stopped while rclpy loaded: nothing of ROS exists yet
    rclpy.init(args=argv, signal_handler_options=SignalHandlerOptions.NO)
    node = None
    try:
        if signals.received:
            return 0  # stopped during rclpy.init: the finally shuts the context down
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
