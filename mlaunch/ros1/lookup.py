"""How a roslaunch file finds packages and runs ``<param command>``, as ROS 1 does.

``$(find pkg)`` is rospack's lookup: the folders of ``ROS_PACKAGE_PATH`` (a folder with a
``package.xml`` is a package; its subfolders are not searched), then Debian's ``/usr/share``
(where Debian installs ROS 1 packages), then mlaunch's own search (installed ROS 2 packages and
source packages near the launch file). ``xacro`` found nowhere is the PyPI xacro mlaunch runs
in-process, so ``$(find xacro)/xacro FILE`` works without a ROS xacro package.
"""

from __future__ import annotations

import os
import shlex
import subprocess
from collections.abc import Callable, Mapping
from typing import Any

from mlaunch.plan.errors import LaunchFileError
from mlaunch.ros.packages import package_name

XACRO_PROGRAMS = ("xacro", "xacro.py")


def ros_package_folders(environ: Mapping[str, str]) -> dict[str, str]:
    """Package name -> folder along ROS_PACKAGE_PATH and /usr/share (first found wins)."""
    found: dict[str, str] = {}
    roots = [p for p in environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if p]
    for root in [*roots, "/usr/share"]:
        _crawl(root, found, depth=0 if root == "/usr/share" else 16)
    return found


def _crawl(folder: str, found: dict[str, str], depth: int) -> None:
    manifest = os.path.join(folder, "package.xml")
    if os.path.isfile(manifest):
        name = package_name(manifest)
        if name and name not in found:
            found[name] = folder
        return
    try:
        entries = sorted(os.scandir(folder), key=lambda e: e.name)
    except OSError:
        return
    for entry in entries:
        if entry.name.startswith(".") or not entry.is_dir():
            continue
        if depth > 0 or os.path.isfile(os.path.join(entry.path, "package.xml")):
            _crawl(entry.path, found, depth - 1)


CATKIN_MARKER = ".catkin"


def catkin_workspaces(environ: Mapping[str, str]) -> list[str]:
    """catkin's workspaces: the ``CMAKE_PREFIX_PATH`` entries with a ``.catkin`` marker, then
    ``/usr`` (where Debian installs ROS 1)."""
    paths = [p for p in environ.get("CMAKE_PREFIX_PATH", "").split(os.pathsep) if p]
    return [p for p in paths if os.path.isfile(os.path.join(p, CATKIN_MARKER))] + ["/usr"]


def catkin_find(package: str, environ: Mapping[str, str]) -> list[str]:
    """Where roslaunch looks for a package's programs before its own folder (catkin_find with
    ``libexec`` and ``share``, the first workspace that has any): ``lib/PKG``, ``libexec/PKG``,
    ``share/PKG`` and the package in the workspace's source spaces (a devel space's marker
    names them)."""
    for workspace in catkin_workspaces(environ):
        found = []
        for sub in ("lib", "libexec", "share"):
            folder = os.path.join(workspace, sub, package)
            if os.path.exists(folder):
                found.append(folder)
        for source in source_spaces(workspace):
            packages: dict[str, str] = {}
            _crawl(source, packages, depth=16)
            if package in packages:
                found.append(packages[package])
        if found:
            return found
    return []


def source_spaces(workspace: str) -> list[str]:
    """The source folders a workspace's ``.catkin`` marker lists (``;``-separated)."""
    if workspace == "/usr":
        return []
    try:
        with open(os.path.join(workspace, CATKIN_MARKER), encoding="utf-8") as f:
            text = f.read()
    except OSError:
        return []
    out: list[str] = []
    for path in text.split(";") if text else []:
        if path and os.path.realpath(path) not in {os.path.realpath(p) for p in out}:
            out.append(path)
    return out


def package_finder(
    launch_file: str, environ: Mapping[str, str], index: Any = None
) -> Callable[[str], str]:
    """``$(find pkg)`` for one resolution (the folders are scanned once); ``index``: the
    run's package search, when there is one."""
    cache: dict[str, str] | None = None

    def find(name: str) -> str:
        nonlocal cache
        if cache is None:
            cache = ros_package_folders(environ)
        if name in cache:
            return cache[name]
        from mlaunch.ros import packages

        search = index or packages.index(environ=environ, launch_files=[launch_file])
        package = search.find(name)
        if package is not None:
            return str(package.share_directory)
        if name == "xacro":
            import xacro

            return os.path.dirname(os.path.abspath(str(xacro.__file__)))
        raise LaunchFileError(f"package {name!r} not found (ROS_PACKAGE_PATH, /usr/share)")

    return find


def command_runner(environ: Mapping[str, str], launch_file: str) -> Callable[[str], str]:
    """``<param command>``: the program's standard output (xacro runs in-process)."""

    def run(command: str) -> str:
        argv = shlex.split(command)
        if not argv:
            raise LaunchFileError("<param command> is empty")
        argv[0] = installed_xacro(argv[0]) or argv[0]
        if os.path.basename(argv[0]) in XACRO_PROGRAMS and not _is_program(argv[0]):
            from mlaunch.launch_ros import xacro
            from mlaunch.ros import packages

            index = packages.index(environ=environ, launch_files=[launch_file])
            rc, out, err = xacro.run_program(["xacro", *argv[1:]], environ, index)
            if rc != 0:
                raise LaunchFileError(xacro.failure_message(argv, rc, err))
            return out
        try:
            done = subprocess.run(argv, capture_output=True, env=dict(environ), check=False)
        except OSError as e:
            raise LaunchFileError(f"cannot run <param command> {command!r}: {e.strerror}")
        if done.returncode != 0:
            raise LaunchFileError(
                f"<param command> {command!r} exited with status {done.returncode}:"
                f" {done.stderr.decode('utf-8', 'replace').strip()}"
            )
        return done.stdout.decode("utf-8")

    return run


def installed_xacro(program: str) -> str | None:
    """``.../xacro.py`` (xacro's name before ROS Melodic) that is not there: the ``xacro``
    beside it when that is a program (the installed ROS 1 xacro), else None."""
    if os.path.basename(program) != "xacro.py" or _is_program(program):
        return None
    sibling = os.path.join(os.path.dirname(program), "xacro")
    return sibling if _is_program(sibling) else None


def renamed_command(command: str) -> str | None:
    """The warning for a ``<param command>`` that runs xacro by its old name, ``xacro.py``
    (what runs instead), or None."""
    try:
        program = shlex.split(command)[0]
    except (ValueError, IndexError):
        return None
    if os.path.basename(program) != "xacro.py" or _is_program(program):
        return None
    instead = installed_xacro(program) or "xacro (the PyPI xacro, inside mlaunch)"
    return (
        f"{program} is xacro's name in ROS 1 releases before Melodic:"
        f" running {instead}, which replaced it"
    )


def _is_program(path: str) -> bool:
    return os.path.isfile(path) and os.access(path, os.X_OK)
