"""Whom ``mlaunch ctl`` talks to: only a run of the caller's own.

A shared log folder (``ROS_LOG_DIR`` in a 1777 folder) lets another user plant a folder that
looks like a run's, with a socket that answers anything. Before a request is sent, the socket
must belong to the caller, in a folder only the caller can write, and the process that listens
on it must run as the caller (SO_PEERCRED, which the kernel fills in: a planted socket cannot
lie about it).
"""

from __future__ import annotations

import os
import socket
import stat
import struct

from mlaunch.commands.ctl import CtlError


def _user(uid: int) -> str:
    import pwd

    try:
        return f"uid {uid} ({pwd.getpwuid(uid).pw_name})"
    except KeyError:
        return f"uid {uid}"


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
