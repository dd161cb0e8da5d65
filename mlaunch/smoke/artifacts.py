"""The evidence of a test run: a folder a CI job keeps when the run failed.

``mlaunch test --artifacts DIR`` writes it always; without the option it is written on a
failure, into ``artifacts/`` of the run's log folder. It holds:

- ``verdict.json``: the verdict as data (``--format json``'s document);
- ``plan.json``: the plan (``--print --format json``'s document);
- ``processes.json``: each process's argv, cwd, environment, the parameters it was given (the
  content of its params files), pid, how it ended, and the last lines of its output;
- ``logs/``: the run's log files (launch.log and each process's, the last LOG_BYTES of each);
- ``backtraces/LABEL.txt``: gdb's backtrace of a process that dumped core, where gdb is
  installed and the core file is where the kernel's core_pattern puts it;
- ``recording.mcap``: the last seconds of the topics the checks named (or ``--record``), from
  the recorder (mlaunch.smoke.recorder), readable by ros2 bag and Foxglove.

The launch panel builds the same folder on demand from the running launch (``verdict`` None:
no verdict.json; no backtraces, since it runs no command) and sends it packed by ``pack``.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
from collections.abc import Mapping, Sequence
from typing import Any

# How much of each log file the folder keeps (the end of it).
LOG_BYTES = 1024 * 1024
# How long gdb may take over one core file.
GDB_TIMEOUT = 60.0
# What ``pack`` puts in one archive at most (bytes of the files, before compression).
PACK_BYTES = 64 * 1024 * 1024


class Bundle:
    """What was written: the folder, its files and their total size."""

    def __init__(self, folder: str) -> None:
        self.folder = folder
        self.files: list[str] = []
        self.notes: list[str] = []

    def path(self, name: str) -> str:
        full = os.path.join(self.folder, name)
        os.makedirs(os.path.dirname(full), exist_ok=True)
        self.files.append(name)
        return full

    def write_text(self, name: str, text: str) -> None:
        with open(self.path(name), "w", encoding="utf-8") as f:
            f.write(text)

    def size(self) -> int:
        total = 0
        for name in self.files:
            try:
                total += os.path.getsize(os.path.join(self.folder, name))
            except OSError:
                pass
        return total

    def line(self) -> str:
        kb = self.size() / 1024
        notes = f"; {'; '.join(self.notes)}" if self.notes else ""
        return f"evidence: {self.folder} ({len(self.files)} files, {kb:.0f} KB){notes}"


def write(
    folder: str,
    *,
    verdict: Mapping[str, Any] | None,
    plan_text: str,
    processes: Sequence[Any],
    rings: Mapping[str, Sequence[str]],
    log_dir: str,
    recorder: Any = None,
    backtraces: bool = True,
) -> Bundle:
    """Write the evidence into ``folder`` (made if missing).

    ``verdict`` None (a run still going has none) leaves verdict.json out; ``backtraces``
    False runs no gdb and says so in the record of a process that dumped core.
    """
    os.makedirs(folder, exist_ok=True)
    bundle = Bundle(folder)
    if verdict is not None:
        bundle.write_text("verdict.json", json.dumps(verdict, indent=2) + "\n")
    bundle.write_text("plan.json", plan_text)
    records = [process_record(p, rings.get(p.label, ())) for p in processes]
    for record, process in zip(records, processes, strict=True):
        if process.core_dumped:
            record["backtrace"] = (
                backtrace(bundle, process)
                if backtraces
                else "not taken here (the failure evidence of mlaunch test takes it)"
            )
    bundle.write_text("processes.json", json.dumps(records, indent=2) + "\n")
    copy_logs(bundle, log_dir)
    if recorder is not None:
        try:
            count, topics = recorder.write(bundle.path("recording.mcap"))
            bundle.notes.append(f"recording.mcap: {count} messages on {topics} topics")
        except Exception as e:  # the rest of the evidence stands without it
            bundle.notes.append(f"no recording: {type(e).__name__}: {e}")
    return bundle


def pack(folder: str, name: str, limit: int = PACK_BYTES) -> tuple[bytes, list[str]]:
    """The files of ``folder`` as a .tar.gz below ``name/`` and those left out: a file that
    would take the archive past ``limit`` bytes is left out (and named in ``name/LEFT_OUT.txt``).
    Only regular files are packed; a link is never followed."""
    import io
    import tarfile
    import time

    files: list[tuple[str, str]] = []
    for root, dirs, names in os.walk(folder):
        dirs.sort()
        for entry in sorted(names):
            full = os.path.join(root, entry)
            if os.path.isfile(full) and not os.path.islink(full):
                files.append((full, os.path.relpath(full, folder)))
    data = io.BytesIO()
    left: list[str] = []
    total = 0
    with tarfile.open(fileobj=data, mode="w:gz") as tar:
        for full, relative in files:
            size = os.path.getsize(full)
            if total + size > limit:
                left.append(f"{relative} ({size} bytes)")
                continue
            total += size
            tar.add(full, arcname=f"{name}/{relative}", recursive=False)
        if left:
            text = f"left out: the archive holds at most {limit} bytes\n" + "\n".join(left)
            info = tarfile.TarInfo(f"{name}/LEFT_OUT.txt")
            payload = (text + "\n").encode()
            info.size, info.mtime = len(payload), int(time.time())
            tar.addfile(info, io.BytesIO(payload))
    return data.getvalue(), left


def process_record(process: Any, lines: Sequence[str]) -> dict[str, Any]:
    """One process as data: what started it, what it was given, how it ended."""
    from mlaunch.engine.process import describe_status

    spec = process.spec
    code = process.returncode
    return {
        "label": process.label,
        "argv": list(process.argv),
        "cwd": spec.cwd,
        "environment": dict(spec.env),
        "environment_changes": dict(spec.env_changes or {}),
        "parameters": parameters(process.argv),
        "node": None if spec.node is None else spec.node.fully_qualified_name,
        "pid": process.pid,
        "restarts": process.restarts,
        "ended": None if code is None else describe_status(code),
        "returncode": code,
        "core_dumped": bool(process.core_dumped),
        "last_output": list(lines),
    }


def parameters(argv: Sequence[str]) -> list[dict[str, str]]:
    """The ``--params-file`` files (their text, read now: they are gone after the run) and the
    ``-p name:=value`` rules of a ROS command line."""
    out: list[dict[str, str]] = []
    items = list(argv)
    for i, item in enumerate(items[:-1]):
        value = items[i + 1]
        if item == "--params-file":
            try:
                with open(value, encoding="utf-8", errors="replace") as f:
                    out.append({"file": value, "content": f.read()})
            except OSError as e:
                out.append({"file": value, "content": f"(not readable: {e.strerror})"})
        elif item == "-p":
            out.append({"rule": value})
    return out


def copy_logs(bundle: Bundle, log_dir: str) -> None:
    """The end of each of the run's log files into ``logs/``."""
    try:
        names = sorted(os.listdir(log_dir)) if log_dir else []
    except OSError:
        return
    for name in names:
        source = os.path.join(log_dir, name)
        if not name.endswith(".log") or not os.path.isfile(source) or os.path.islink(source):
            continue
        try:
            with open(source, "rb") as f:
                f.seek(max(0, os.path.getsize(source) - LOG_BYTES))
                data = f.read()
        except OSError:
            continue
        with open(bundle.path(os.path.join("logs", name)), "wb") as out:
            out.write(data)


def backtrace(bundle: Bundle, process: Any) -> str:
    """gdb's backtrace of ``process``'s core file into backtraces/, or why there is none."""
    gdb = shutil.which("gdb")
    core = core_file(process)
    if core is None:
        return "no core file found where kernel.core_pattern puts it"
    if gdb is None:
        return f"core file {core}; gdb is not installed, so no backtrace"
    program = shutil.which(process.argv[0]) or process.argv[0]
    try:
        done = subprocess.run(
            [gdb, "-batch", "-ex", "thread apply all bt", program, core],
            capture_output=True,
            text=True,
            timeout=GDB_TIMEOUT,
            stdin=subprocess.DEVNULL,
        )
    except (OSError, subprocess.TimeoutExpired) as e:
        return f"core file {core}; gdb failed: {e}"
    name = os.path.join("backtraces", f"{process.label}.txt")
    bundle.write_text(name, done.stdout + done.stderr)
    return name


def core_file(process: Any) -> str | None:
    """The core file of a process that dumped core, for a core_pattern that writes a file
    (``core``, ``core.%p``, an absolute pattern with %p / %e); None when it is piped away."""
    try:
        with open("/proc/sys/kernel/core_pattern", encoding="utf-8") as f:
            pattern = f.read().strip()
    except OSError:
        return None
    if not pattern or pattern.startswith("|"):
        return None
    name = os.path.basename(process.argv[0])[:15]
    path = pattern.replace("%p", str(process.pid)).replace("%e", name).replace("%%", "%")
    folder = process.spec.cwd or os.getcwd()
    path = path if os.path.isabs(path) else os.path.join(folder, path)
    for candidate in (path, f"{path}.{process.pid}"):
        if "%" not in candidate and os.path.isfile(candidate):
            return candidate
    return None
