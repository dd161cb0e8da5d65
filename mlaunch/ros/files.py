"""Temporary files the ROS layer writes for its processes (params files), without tempfile.

tempfile costs ~6 ms to import (it pulls in shutil, random and the compression modules), and a
launch with a node's parameters writes its files before the first child starts.
"""

from __future__ import annotations

import os


def write_temp(prefix: str, text: str, temp_dir: str | None) -> str:
    """Write ``text`` to a new file ``<temp_dir>/<prefix>XXXXXXXX`` (mode 0600); return its path.

    The name is new (created exclusively), as tempfile.NamedTemporaryFile(delete=False) makes
    it; without ``temp_dir`` the file goes where tempfile would put it.
    """
    if temp_dir is None:
        import tempfile

        temp_dir = tempfile.gettempdir()
    data = text.encode("utf-8")
    for _ in range(100):
        path = os.path.join(temp_dir, prefix + os.urandom(4).hex())
        try:
            fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
        except FileExistsError:
            continue
        try:
            write_all(fd, data)
        finally:
            os.close(fd)
        return path
    raise FileExistsError(f"no unused file name {prefix}XXXXXXXX in {temp_dir}")


def write_all(fd: int, data: bytes) -> None:
    """Write all of ``data`` to ``fd`` (os.write may take only part of it)."""
    view = memoryview(data)
    while view:
        view = view[os.write(fd, view) :]
