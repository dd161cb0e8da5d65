"""Helpers for a package's own tests of its launch files.

``check_launch_file(path, **arguments)`` is ROS 1's ``roslaunch_add_file_check`` as a pytest
(or unittest) assertion: one test per launch file fails with every error a run would stop at
before starting anything (the file does not load, an undeclared ``$(var y)``, a required
argument not given, a package, an executable or a parameter file that is not there), each at its
file:line, and nothing is started. With ``jazzy=True`` (the default) what ROS 2 Jazzy's
ros2 launch would reject or read differently fails it too (``mlaunch FILE --check``).

    from mlaunch.testing import check_launch_file

    def test_bringup_launch_file():
        check_launch_file("launch/bringup.launch.py", use_sim_time="true")
"""

from __future__ import annotations

import os
from typing import Any

__all__ = ["LaunchFileCheckError", "check_launch_file"]


class LaunchFileCheckError(AssertionError):
    """The launch file has findings; ``findings`` holds them as ``file:line: message`` lines."""

    def __init__(self, path: str, findings: list[str]) -> None:
        count = f"{len(findings)} finding{'s' if len(findings) != 1 else ''}"
        super().__init__(f"{path}: {count}\n" + "\n".join(findings))
        self.path = path
        self.findings = findings


def check_launch_file(
    path: str | os.PathLike[str],
    *,
    jazzy: bool = True,
    package_path: list[str] | None = None,
    **arguments: Any,
) -> None:
    """Check the launch file at ``path`` with ``name:=value`` ``arguments``; raise
    LaunchFileCheckError (an AssertionError) listing every finding. ``package_path``: folders
    to find packages in, as ``--package-path``."""
    from mlaunch import compat
    from mlaunch.app.options import parse_options
    from mlaunch.app.pipeline import find_launch_file, package_search
    from mlaunch.check import loading, portability
    from mlaunch.ros.search import searching

    compat.install()  # launch files import the ROS 2 names (launch, launch_ros ...)
    argv = [os.fspath(path), *(f"{k}:={_text(v)}" for k, v in arguments.items())]
    for folder in package_path or ():
        argv += ["--package-path", folder]
    opts = parse_options([*argv, "--check"])
    from mlaunch.plan.errors import MlaunchError

    try:
        with searching(package_search(opts, None)):
            found = find_launch_file(opts)
    except MlaunchError as error:  # no such file, no such package
        raise LaunchFileCheckError(os.fspath(path), [str(error)]) from None
    findings = portability.check(found) if jazzy else []
    findings += loading.check_run(opts, found)
    if findings:
        raise LaunchFileCheckError(found, [str(f) for f in findings])


def _text(value: Any) -> str:
    """A Python value as the text a command line would give (True -> 'true')."""
    if isinstance(value, bool):
        return "true" if value else "false"
    return str(value)
