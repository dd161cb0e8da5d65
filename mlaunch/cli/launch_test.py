"""The ``launch_test`` program (pyproject's scripts): launch_testing's runner
(mlaunch.launch_testing.launch_test), with the ROS 2 module names served by mlaunch first."""

from __future__ import annotations

from mlaunch import compat


def program() -> None:
    compat.install()
    from mlaunch.launch_testing.launch_test import program as run

    run()


if __name__ == "__main__":
    program()
