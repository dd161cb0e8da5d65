"""The environment a ROS 1 program gets: not mlaunch's own. ROS 1's Python programs run with the
system's Python (``system_python_env``), and what ``--print`` shows starts from the environment
the user's shell gave mlaunch (``shell_environ``): both leave out what the ROS 2 wheels'
bootstrap and mlaunch's virtual environment put in mlaunch's own process."""

from __future__ import annotations

import os
import sys
from collections.abc import Mapping

# What mlaunch's own process has that is not the user's: the ROS 2 wheels' bootstrap (their
# ``.pth`` re-executes Python with their libraries on LD_LIBRARY_PATH and this guard set).
BOOTSTRAP_GUARD = "_ROS_WHEELS_BOOTSTRAP_COMPLETE"


def system_python_env(env: Mapping[str, str]) -> dict[str, str]:
    """The environment without mlaunch's virtual environment: ROS 1's Python programs
    (``#!/usr/bin/env python3``) must find the system's Python and its packages, and no ROS 1
    program gets the ROS 2 wheels' libraries (LD_LIBRARY_PATH entries inside the venv) or
    their bootstrap's guard."""
    out = dict(env)
    venv = sys.prefix if sys.prefix != sys.base_prefix else out.get("VIRTUAL_ENV")
    system_first(out)
    out.pop("VIRTUAL_ENV", None)
    out.pop("PYTHONHOME", None)
    out.pop(BOOTSTRAP_GUARD, None)
    if venv:
        inside = os.path.realpath(venv) + os.sep

        def keep(entry: str) -> bool:
            return bool(entry) and not (os.path.realpath(entry) + os.sep).startswith(inside)

        for name in ("PATH", "PYTHONPATH", "LD_LIBRARY_PATH"):
            if name in out:
                kept = [e for e in out[name].split(os.pathsep) if keep(e)]
                if kept:
                    out[name] = os.pathsep.join(kept)
                else:
                    out.pop(name)
    return out


SYSTEM_PYTHON = "/usr/bin/python3"


def system_first(env: dict[str, str]) -> None:
    """``python3`` on PATH is the system's (where ROS 1's packages are): its folder goes
    first when another one (a pyenv shim, a virtual environment) would be found before it."""
    import shutil

    if not os.access(SYSTEM_PYTHON, os.X_OK):
        return
    found = shutil.which("python3", path=env.get("PATH", os.defpath))
    if found is not None and os.path.realpath(found) == os.path.realpath(SYSTEM_PYTHON):
        return
    folder = os.path.dirname(SYSTEM_PYTHON)
    rest = [e for e in env.get("PATH", "").split(os.pathsep) if e and e != folder]
    env["PATH"] = os.pathsep.join([folder, *rest])


def shell_environ(environ: Mapping[str, str]) -> dict[str, str]:
    """The environment the user's shell gave mlaunch: without what the ROS 2 wheels' bootstrap
    added to mlaunch's own (their libraries on LD_LIBRARY_PATH, its guard)."""
    out = dict(environ)
    if out.pop(BOOTSTRAP_GUARD, None) is None:
        return out
    inside = os.path.realpath(sys.prefix) + os.sep
    kept = [
        e
        for e in out.get("LD_LIBRARY_PATH", "").split(os.pathsep)
        if e and not (os.path.realpath(e) + os.sep).startswith(inside)
    ]
    if kept:
        out["LD_LIBRARY_PATH"] = os.pathsep.join(kept)
    else:
        out.pop("LD_LIBRARY_PATH", None)
    return out
