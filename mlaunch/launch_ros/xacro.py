"""xacro run inside mlaunch for ``Command(['xacro ', path, ' arg:=value'])``.

Starting the ``xacro`` program costs an interpreter start and the xacro import for every robot
description; running the same PyPI ``xacro`` package in-process gives byte-identical output (it
is xacro's own ``main()`` with the same argv: ``name:=value`` mappings, ``-o``, ``--inorder``,
``--deps``) in a fraction of the time, and the same stderr and exit status, so Command's
``on_stderr`` policy applies exactly as it would to the program.

What differs on purpose, while xacro runs here:

- ``$(find pkg)`` and ``${find('pkg')}`` resolve through mlaunch.ros.packages (installed
  packages first, then source packages near the launch file), not ament_index_python; only
  xacro's own references are swapped, so a real ament_index_python elsewhere is untouched.
- ``$(env)``/``$(optenv)`` read the launch context's environment, which is what the program
  would have inherited.
- a failure is a SubstitutionFailure naming the xacro file, the line when xacro gives one, the
  macro and include chain, and xacro's own message, instead of "exit status 2".

xacro keeps module-level state (file stack, include list, root dir, verbosity); runs are
serialised by a lock and that state is restored afterwards, so a launch file that calls
``xacro.process_doc`` itself later is not affected.
"""

from __future__ import annotations

import io
import os
import re
import sys
import threading
import types
from collections.abc import Iterator, Mapping
from contextlib import contextmanager

from mlaunch.launch.substitutions.command import IN_PROCESS_COMMANDS
from mlaunch.plan.errors import SubstitutionFailure

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext
    from mlaunch.ros.packages import PackageIndex

PROGRAM_NAMES = ("xacro", "xacro.py")
_LOCK = threading.RLock()
_ANSI = re.compile(r"\x1b\[[0-9;]*m")
_LOCATION_PREFIXES = (
    "when processing file:",
    "in file:",
    "included from:",
    "when instantiating macro:",
    "instantiated from:",
)


def register() -> None:
    """Let Command() run ``xacro`` (and the old ``xacro.py``) in-process."""
    for name in PROGRAM_NAMES:
        IN_PROCESS_COMMANDS[name] = run


def run(argv: list[str], context: LaunchContext) -> tuple[int, str, str]:
    """Run ``argv`` (``xacro ...``) as the xacro program would; fail loudly if xacro fails."""
    from mlaunch.ros import packages

    index = packages.for_context(context)
    rc, out, err = run_program(argv, context.environment, index)
    if rc != 0:
        raise SubstitutionFailure(failure_message(argv, rc, err))
    return rc, out, err


def run_program(
    argv: list[str], environ: Mapping[str, str], index: PackageIndex
) -> tuple[int, str, str]:
    """xacro's ``main()`` on argv with captured stdout/stderr: (exit status, stdout, stderr)."""
    import xacro

    out, err = io.StringIO(), io.StringIO()
    with _LOCK, _isolated(xacro, argv, out, err), _lookups(environ, index):
        try:
            xacro.main()
            rc = 0
        except SystemExit as e:
            rc = _exit_status(e.code, err)
        except Exception as e:  # the program would die with a traceback
            err.write(f"{type(e).__name__}: {e}\n")
            rc = 1
    return rc, out.getvalue(), err.getvalue()


def _exit_status(code: Any, err: io.StringIO) -> int:
    if code is None:
        return 0
    if isinstance(code, int):
        return code
    err.write(f"{code}\n")  # sys.exit("message") prints it and exits 1
    return 1


class _SysView(types.SimpleNamespace):
    """``sys`` as xacro and optparse see it during a run: our argv and captured streams."""

    def __getattr__(self, name: str) -> Any:
        return getattr(sys, name)


class _OsView(types.SimpleNamespace):
    """``os`` as xacro's substitution args see it: the launch context's environment."""

    def __getattr__(self, name: str) -> Any:
        return getattr(os, name)


@contextmanager
def _isolated(
    xacro: types.ModuleType, argv: list[str], out: io.StringIO, err: io.StringIO
) -> Iterator[None]:
    """Point xacro's ``sys`` at captured streams and save/restore its module state.

    Only xacro's (and optparse's) own ``sys`` names are swapped, never ``sys.stdout`` itself,
    so output other threads print meanwhile (the supervisor's) is not captured.
    """
    import optparse  # xacro's own command-line parser; imported with xacro, not before

    from xacro import color

    view = _SysView(argv=list(argv), stdout=out, stderr=err)
    modules: tuple[Any, ...] = (xacro, color, optparse)
    saved_sys = [m.sys for m in modules]
    saved_state = {
        name: getattr(xacro, name)
        for name in ("filestack", "macrostack", "all_includes", "root_dir", "verbosity")
    }
    xacro.all_includes = []  # type: ignore[attr-defined]
    for module in modules:
        module.sys = view
    try:
        yield
    finally:
        for module, saved in zip(modules, saved_sys, strict=True):
            module.sys = saved
        for name, value in saved_state.items():
            setattr(xacro, name, value)


@contextmanager
def _lookups(environ: Mapping[str, str], index: PackageIndex) -> Iterator[None]:
    """``$(find)``, ``${find()}``, ``$(env)`` and ``$(optenv)`` answered from mlaunch."""
    from xacro import substitution_args as sa

    def find(package: str) -> str:
        return index.get(package).share_directory

    saved = (sa.os, sa._eval_find, sa._eval_dict["find"])
    sa.os = _OsView(environ=dict(environ))
    sa._eval_find = find
    sa._eval_dict["find"] = find
    try:
        yield
    finally:
        sa.os, sa._eval_find, sa._eval_dict["find"] = saved


# --- failure messages ----------------------------------------------------------------------------


def failure_message(argv: list[str], rc: int, stderr: str) -> str:
    """One line from xacro's stderr: file[:line]: message (macro, include chain)."""
    lines = [_ANSI.sub("", line).strip() for line in stderr.splitlines()]
    start = next((i for i, line in enumerate(lines) if _is_error_line(line)), None)
    message: list[str] = []
    files: list[str] = []
    included: list[str] = []
    macros: list[str] = []
    for line in lines[start or 0 :]:
        prefix = next((p for p in _LOCATION_PREFIXES if line.startswith(p)), None)
        if prefix is None:
            if line and not (files or included or macros):
                message.append(line)
            continue
        value = line[len(prefix) :].strip()
        if prefix in ("when processing file:", "in file:"):
            files.append(value)
        elif prefix == "included from:":
            included.append(value)
        else:
            macros.append(value)
    if start is None or not files:
        last = next((line for line in reversed(lines) if line), f"exit status {rc}")
        return f"xacro failed (exit status {rc}): {last} [{' '.join(argv)}]"
    text = _tidy("; ".join(message))
    where = files[0]
    line_number = re.search(r"\bline (\d+)", text)
    if line_number:
        where += f":{line_number.group(1)}"
    context = []
    if macros:
        context.append("in macro " + ", instantiated from ".join(macros))
    if included:
        context.append("included from " + ", ".join(included))
    detail = f" ({'; '.join(context)})" if context else ""
    return f"xacro failed on {where}: {text}{detail}"


def _is_error_line(line: str) -> bool:
    return line.startswith(("error: ", "XML parsing error:"))


def _tidy(text: str) -> str:
    """Drop the ``error:`` prefix and the repetition in xacro's wrapped exceptions.

    xacro reports a foreign exception as ``<class 'pkg.Error'>: text text``.
    """
    text = re.sub(r"^error: ", "", text)
    wrapped = re.fullmatch(r"<class '(?:[\w.]+\.)?(\w+)'>: (.+) \2(.*)", text, re.DOTALL)
    if wrapped:
        text = f"{wrapped.group(1)}: {wrapped.group(2)}{wrapped.group(3)}"
    return text


__all__ = ["PROGRAM_NAMES", "failure_message", "register", "run", "run_program"]
