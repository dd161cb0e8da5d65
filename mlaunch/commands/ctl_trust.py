"""Whom ``mlaunch ctl`` talks to: only a run of the caller's own.

A shared log folder (``ROS_LOG_DIR`` in a 1777 folder) lets another user plant a folder that
looks like a run's, with a socket that answers anything, or that leads to a socket of the
caller's own other run: a ``latest`` that is a folder, a ``control`` that is a symlink, a
``control/where`` naming any socket. So whatever locates a run is the caller's own and is not
followed through links (``locate``): ``latest`` only as a symlink the caller made, the run folder,
its ``control`` folder (a real folder, 0700) and ``where`` (a regular file) owned by the caller.
Before a request is sent, the socket must belong to the caller, in a folder only the caller can
write, and the process that listens on it must run as the caller (SO_PEERCRED, which the kernel
fills in: a planted socket cannot lie about it).
"""

from __future__ import annotations

import errno
import os
import socket
import stat
import struct

from mlaunch.commands.ctl_error import CtlError
from mlaunch.engine.ownership import user_name as _user
from mlaunch.parts.control_socket import FOLDER, NAME, WHERE

# A ``where`` file holds one path; anything longer is not mlaunch's.
MAX_WHERE = 4096


def untrusted(path: str) -> str:
    """Why the socket at ``path`` is not the caller's own ("" when it is, or is gone)."""
    me = os.geteuid()
    try:
        st = os.lstat(path)
    except OSError:
        return ""  # gone: connecting says the run ended
    if not stat.S_ISSOCK(st.st_mode):
        return f"{path} is not a socket"
    if st.st_uid != me:
        return f"the control socket {path} belongs to {_user(st.st_uid)}, not to you ({_user(me)})"
    folder = os.path.dirname(path)
    try:
        fst = os.stat(folder)
    except OSError as e:
        return f"its folder {folder} cannot be checked: {e.strerror or e}"
    if fst.st_uid != me or fst.st_mode & 0o022:
        return (
            f"the control socket's folder {folder} belongs to {_user(fst.st_uid)} with mode"
            f" {stat.S_IMODE(fst.st_mode):o}: someone else could have put the socket there"
            " (a run's own is yours, 700)"
        )
    return ""


def own_entry(path: str) -> str:
    """Why the run named by ``path`` (an entry of the log base: a run folder, ``latest``) is not
    to be followed ("" when it is the caller's): a symlink the caller did not make, a folder
    another user owns, a link to one."""
    me = os.geteuid()
    try:
        st = os.lstat(path)
    except OSError as e:
        return f"{path} cannot be checked: {e.strerror or e}"
    if stat.S_ISLNK(st.st_mode) and st.st_uid != me:
        return f"{path} is a symlink made by {_user(st.st_uid)}, not by you ({_user(me)})"
    if not stat.S_ISLNK(st.st_mode) and os.path.basename(path) == "latest":
        return f"{path} is not the symlink a run makes but a {_kind(st.st_mode)}"
    return _own_folder(os.path.realpath(path))


def _own_folder(folder: str) -> str:
    me = os.geteuid()
    try:
        st = os.stat(folder)
    except OSError as e:
        return f"{folder} cannot be checked: {e.strerror or e}"
    if not stat.S_ISDIR(st.st_mode):
        return f"{folder} is a {_kind(st.st_mode)}, not a run's log folder"
    if st.st_uid != me:
        return f"the run folder {folder} belongs to {_user(st.st_uid)}, not to you ({_user(me)})"
    return ""


def _kind(mode: int) -> str:
    if stat.S_ISDIR(mode):
        return "folder"
    if stat.S_ISLNK(mode):
        return "symlink"
    return "socket" if stat.S_ISSOCK(mode) else "file"


def locate(folder: str) -> tuple[str | None, str]:
    """(the control socket of the run logging to ``folder``, "") found only through what the
    caller owns and never through a link; (None, why) when something on the way is not the
    caller's; (None, "") when the run has no socket (it ended)."""
    why = _own_folder(folder)
    if why:
        return None, why
    me = os.geteuid()
    control = os.path.join(folder, FOLDER)
    try:
        st = os.lstat(control)
    except OSError:
        return None, ""
    if not stat.S_ISDIR(st.st_mode) or st.st_uid != me or st.st_mode & 0o022:
        return None, (
            f"{control} is a {_kind(st.st_mode)} of {_user(st.st_uid)} with mode"
            f" {stat.S_IMODE(st.st_mode):o} (a run's own is a folder of yours, 700)"
        )
    path = os.path.join(control, NAME)
    try:
        if stat.S_ISSOCK(os.lstat(path).st_mode):
            return path, ""
    except OSError:
        pass
    return _where(os.path.join(control, WHERE), me)


def _where(where: str, me: int) -> tuple[str | None, str]:
    """The socket a run's ``where`` file names (the log folder took no socket)."""
    try:
        fd = os.open(where, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC)
    except OSError as e:
        return None, "" if e.errno == errno.ENOENT else f"{where} cannot be read: {e.strerror or e}"
    with open(fd, "rb") as f:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode) or st.st_uid != me or st.st_mode & 0o022:
            return None, (
                f"{where} is a {_kind(st.st_mode)} of {_user(st.st_uid)} with mode"
                f" {stat.S_IMODE(st.st_mode):o} (a run's own is a file of yours, 600)"
            )
        text = f.read(MAX_WHERE + 1)
    named = text.decode("utf-8", "replace").strip()
    if len(text) > MAX_WHERE or not os.path.isabs(named) or "\n" in named:
        return None, f"{where} does not name one socket: {named[:80]!r}"
    try:
        return (named, "") if stat.S_ISSOCK(os.stat(named).st_mode) else (None, "")
    except OSError:
        return None, ""


def check_place(path: str) -> None:
    """Raise unless the socket at ``path`` and its folder are the caller's own."""
    why = untrusted(path)
    if why:
        raise CtlError(f"{why}; not a run of yours: nothing was sent to it")


def check_peer(sock: socket.socket, path: str) -> int:
    """The pid of the process listening on ``sock``; raise unless it runs as the caller."""
    me = os.geteuid()
    size = struct.calcsize("3i")
    pid, uid, _gid = struct.unpack(
        "3i", sock.getsockopt(socket.SOL_SOCKET, socket.SO_PEERCRED, size)
    )
    if uid != me:
        raise CtlError(
            f"the control socket {path} is served by pid {pid} of {_user(uid)}, not by you"
            f" ({_user(me)}): not a run of yours: nothing was sent to it"
        )
    return int(pid)
