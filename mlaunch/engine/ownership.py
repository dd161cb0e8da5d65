"""Who may change a folder: the checks behind a log base, an export folder and ctl's trust.

A folder another user owns, or one others may write into without the sticky bit, lets them
swap what mlaunch made in it for a link to a file of the caller's (a run's log folder, a unit).
"""

from __future__ import annotations

import os
import stat


def user_name(uid: int) -> str:
    """``uid 65534 (nobody)``: a uid as errors name it."""
    import pwd

    try:
        return f"uid {uid} ({pwd.getpwuid(uid).pw_name})"
    except KeyError:
        return f"uid {uid}"


def others_can_write(st: os.stat_result) -> bool:
    """Whether someone besides the owner may add, remove or rename entries of a folder."""
    if st.st_mode & 0o002:
        return True
    if not st.st_mode & 0o020:
        return False
    import grp
    import pwd

    try:
        group = grp.getgrgid(st.st_gid)
        owner = pwd.getpwuid(st.st_uid).pw_name
    except KeyError:
        return True
    # Only a user's private group (umask 002 setups: the group named after them, nobody else
    # in it) lets no one else in.
    return group.gr_name != owner or any(member != owner for member in group.gr_mem)


def unsafe_base(path: str) -> str:
    """Why the folder ``path`` is no place for the caller's files ("" when it is): it, or a
    folder above it, belongs to another user (not root), or others can write into it without
    the sticky bit (a sticky 1777 folder, like /tmp, keeps each one's entries their own)."""
    me = os.geteuid()
    folder = os.path.realpath(path)
    while True:
        try:
            st = os.stat(folder)
        except OSError as e:
            return f"{folder} cannot be checked: {e.strerror or e}"
        if st.st_uid not in (me, 0):
            return f"{folder} belongs to {user_name(st.st_uid)}, not to you ({user_name(me)})"
        if not st.st_mode & stat.S_ISVTX and others_can_write(st):
            return f"{folder} has mode {stat.S_IMODE(st.st_mode):o}: others can write into it"
        parent = os.path.dirname(folder)
        if parent == folder:
            return ""
        folder = parent
