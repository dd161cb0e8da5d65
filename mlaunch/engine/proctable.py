"""The process table as /proc shows it: what the guard and the stray sweep read.

Two ways to find a run's processes. ``tree`` walks /proc/<pid>/task/*/children down from one
process (a few files per descendant: what the supervisor, a subreaper, needs at shutdown).
``scan``/``marked`` read every process and its environment for the run's marker
(``MLAUNCH_RUN_ID=<id>``, inherited by grandchildren even in sessions of their own): what the
guard needs once mlaunch is gone and nothing is left to walk from. Plain functions over plain
records, so the guard's fork and the start-up path pay nothing to import them.
"""

from __future__ import annotations

import os
import time

MARKER = "MLAUNCH_RUN_ID"


class ProcInfo:
    """The few fields of /proc/<pid>/stat a sweep needs (a plain class: cheap to import)."""

    __slots__ = ("pgrp", "pid", "ppid", "state")

    def __init__(self, pid: int, ppid: int, pgrp: int, state: str) -> None:
        self.pid = pid
        self.ppid = ppid
        self.pgrp = pgrp
        self.state = state

    @property
    def zombie(self) -> bool:
        return self.state in ("Z", "X")

    def __repr__(self) -> str:
        return f"ProcInfo(pid={self.pid}, ppid={self.ppid}, pgrp={self.pgrp}, state={self.state!r})"


def read_file(path: str, limit: int = 1 << 20) -> bytes:
    """A /proc file's bytes (read in one pass: /proc files have no size to ask for)."""
    fd = os.open(path, os.O_RDONLY | os.O_CLOEXEC)
    try:
        chunks = []
        size = 0
        while size < limit:
            data = os.read(fd, 65536)
            if not data:
                break
            chunks.append(data)
            size += len(data)
        return b"".join(chunks)
    finally:
        os.close(fd)


def scan() -> list[ProcInfo]:
    """Every process visible in /proc (those that vanish while reading are skipped)."""
    out = []
    for name in os.listdir("/proc"):
        if not name.isdigit():
            continue
        info = proc_info(int(name))
        if info is not None:
            out.append(info)
    return out


def descendants(root: int, procs: list[ProcInfo] | None = None) -> list[ProcInfo]:
    """Living (non-zombie) descendants of ``root``, at any depth."""
    procs = scan() if procs is None else procs
    children: dict[int, list[ProcInfo]] = {}
    for p in procs:
        children.setdefault(p.ppid, []).append(p)
    out: list[ProcInfo] = []
    todo = [root]
    while todo:
        for child in children.get(todo.pop(), ()):
            todo.append(child.pid)
            if not child.zombie:
                out.append(child)
    return out


def proc_info(pid: int) -> ProcInfo | None:
    """One process's /proc/<pid>/stat fields (None once it is gone)."""
    try:
        data = read_file(f"/proc/{pid}/stat")
    except OSError:
        return None
    # The command name is in parentheses and may itself contain ') ': cut at the last one.
    fields = data[data.rfind(b")") + 2 :].split(b" ", 4)
    try:
        return ProcInfo(pid, int(fields[1]), int(fields[2]), fields[0].decode())
    except (IndexError, ValueError):
        return None


_children_files: bool | None = None


def children_files() -> bool:
    """Whether the kernel has /proc/<pid>/task/<tid>/children (CONFIG_PROC_CHILDREN)."""
    global _children_files
    if _children_files is None:
        me = os.getpid()
        _children_files = os.path.exists(f"/proc/{me}/task/{me}/children")
    return _children_files


def tree(root: int) -> list[ProcInfo]:
    """Living (non-zombie) descendants of ``root``, at any depth, without a full /proc scan.

    Follows /proc/<pid>/task/*/children down from ``root`` (every thread's list: a child forked
    by a thread, or re-parented to a subreaper, may be listed under any of them). That reads a
    few files per descendant instead of every process's stat; without the children files (an
    old or stripped kernel) it falls back to ``descendants``.
    """
    if not children_files():
        return descendants(root)
    out: list[ProcInfo] = []
    seen = {root}
    todo = [root]
    while todo:
        pid = todo.pop()
        try:
            tids = os.listdir(f"/proc/{pid}/task")
        except OSError:
            continue  # gone since its parent listed it
        for tid in tids:
            try:
                listed = read_file(f"/proc/{pid}/task/{tid}/children").split()
            except OSError:
                continue  # the thread ended
            for word in listed:
                child = int(word)
                if child in seen:
                    continue
                seen.add(child)
                info = proc_info(child)
                if info is None or info.zombie:
                    continue  # a zombie has no children left: they were re-parented
                out.append(info)
                todo.append(child)
    return out


def _environ(pid: int) -> bytes | None:
    try:
        return read_file(f"/proc/{pid}/environ")
    except OSError:
        return None  # gone, or not ours to read


# Waits before looking again at a process whose environment reads empty (see ``marked``).
EXEC_RETRIES = (0.002, 0.004, 0.008, 0.016)


def marked(run_id: str, procs: list[ProcInfo] | None = None) -> list[ProcInfo]:
    """Living processes of this run, found by the marker in their environment.

    A process in the middle of execve() shows an empty environment for a moment (its new
    memory has no environment block yet), so one that reads empty and is not a kernel thread
    is looked at again a few times, ~30 ms at most: a stray caught exec'ing would be missed.
    """
    procs = scan() if procs is None else procs
    me = os.getpid()
    entry = f"{MARKER}={run_id}".encode()
    found: list[ProcInfo] = []
    blank: list[ProcInfo] = []
    for p in procs:
        if p.zombie or p.pid == me:
            continue
        env = _environ(p.pid)
        if env == b"" and p.ppid not in (0, 2):  # kernel threads are children of kthreadd (2)
            blank.append(p)
        elif env and entry in env.split(b"\0"):
            found.append(p)
    for pause in EXEC_RETRIES:
        if not blank:
            break
        time.sleep(pause)
        still: list[ProcInfo] = []
        for p in blank:
            env = _environ(p.pid)
            if env == b"":
                still.append(p)
            elif env and entry in env.split(b"\0"):
                found.append(p)
        blank = still
    return found
