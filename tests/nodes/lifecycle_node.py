#!/usr/bin/env python3
"""Test managed node (rclpy.lifecycle.Node 'lifecycle_node') for lifecycle bring-up tests.

    python lifecycle_node.py [--fail-configure] [--fail-activate] [--crash-on-activate]
                             [--ros-args -r __node:=camera -r __ns:=/robot1 ...]

- Starts 'unconfigured' and waits for transitions on `<fqn>/change_state`.
- When active, publishes std_msgs/String 'status N' on `status` at 5 Hz (a lifecycle
  publisher, so nothing goes out while inactive).
- Prints one stdout line per transition callback, flushed: `transition <label>: <result>`,
  e.g. `transition configure: success`, `transition activate: failure`.
- `--fail-configure` / `--fail-activate` make that callback return FAILURE (the node stays in
  its previous state); `--crash-on-activate` prints `transition activate: crash` and exits at
  once with status 3 without cleaning up, as a segfaulting driver would (minus the core).
SIGINT/SIGTERM end it with status 0.
"""

from __future__ import annotations

import argparse
import os
from typing import Any

from _ros_main import main, split_args

CRASH_STATUS = 3


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="lifecycle_node.py", description=__doc__.splitlines()[0])
    parser.add_argument("--fail-configure", action="store_true")
    parser.add_argument("--fail-activate", action="store_true")
    parser.add_argument("--crash-on-activate", action="store_true")
    return parser


def _say(label: str, result: str) -> None:
    print(f"transition {label}: {result}", flush=True)


def build(argv: list[str]) -> Any:
    from rclpy.lifecycle import Node, State, TransitionCallbackReturn
    from std_msgs.msg import String

    options = split_args(_parser(), argv)
    success, failure = TransitionCallbackReturn.SUCCESS, TransitionCallbackReturn.FAILURE

    class LifecycleTestNode(Node):
        """The managed node; each callback reports itself, then defers to rclpy's defaults."""

        def __init__(self) -> None:
            super().__init__("lifecycle_node")
            self.sent = 0
            # Our own flag: rclpy's LifecyclePublisher.on_deactivate forgets to disable itself.
            self.active = False
            self.status = self.create_lifecycle_publisher(String, "status", 10)
            self.create_timer(0.2, self.publish)

        def publish(self) -> None:
            if self.active:
                self.sent += 1
                self.status.publish(String(data=f"status {self.sent}"))

        def _finish(self, label: str, fail: bool, state: State, default: Any) -> Any:
            result = failure if fail else default(state)
            _say(label, "success" if result == success else result.name.lower())
            return result

        def on_configure(self, state: State) -> Any:
            return self._finish("configure", options.fail_configure, state, super().on_configure)

        def on_activate(self, state: State) -> Any:
            if options.crash_on_activate:
                _say("activate", "crash")
                os._exit(CRASH_STATUS)
            result = self._finish("activate", options.fail_activate, state, super().on_activate)
            self.active = result == success
            return result

        def on_deactivate(self, state: State) -> Any:
            self.active = False
            return self._finish("deactivate", False, state, super().on_deactivate)

        def on_cleanup(self, state: State) -> Any:
            return self._finish("cleanup", False, state, super().on_cleanup)

        def on_shutdown(self, state: State) -> Any:
            self.active = False
            return self._finish("shutdown", False, state, super().on_shutdown)

        def on_error(self, state: State) -> Any:
            self.active = False
            return self._finish("error", False, state, super().on_error)

    return LifecycleTestNode()


if __name__ == "__main__":
    main(build)
