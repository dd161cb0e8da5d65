"""The folder ``mlaunch export`` writes into: the user's own, and written without following links.

Units are installed by root and run as whoever they name, so whoever can write into the folder
before installation owns the robot. The folder must belong to the user and be writable by no one
else (another user's empty folder is refused, not written into); a new one is made 0755
whatever the umask. Every file is opened below the folder's descriptor with ``O_NOFOLLOW``
after what stood at its name is removed (``--force``: a planted symlink is replaced, never
followed), with its mode set explicitly: units 0644, the environment and params 0600.
"""

from __future__ import annotations

import errno
import os
import stat

from mlaunch.engine.ownership import others_can_write, unsafe_base
from mlaunch.engine.ownership import user_name as _user
from mlaunch.plan.errors import UsageError

FOLDER_MODE = 0o755
PRIVATE_FOLDER_MODE = 0o700


class Folder:
    """An export folder, open as a descriptor once its owner and mode are checked."""

    def __init__(self, path: str, fd: int) -> None:
        self.path = path
        self.fd = fd

    @classmethod
    def open(cls, path: str, *, force: bool) -> Folder:
        """Open (or make) ``path``; UsageError when it is not the user's alone, is a link, or
        holds files without ``force``."""
        existing = os.path.dirname(os.path.abspath(path))
        while not os.path.isdir(existing):
            existing = os.path.dirname(existing)
        above = unsafe_base(existing)  # before anything is made in it
        if above:
            raise UsageError(
                f"{path!r} is in a folder others could change: {above}; they could swap the"
                " units before they are installed; export into a folder of your own"
            )
        made = False
        try:
            os.mkdir(path, FOLDER_MODE)
            made = True
        except FileExistsError:
            pass
        except FileNotFoundError:
            _make_parents(os.path.dirname(os.path.abspath(path)))
            os.mkdir(path, FOLDER_MODE)
            made = True
        try:
            fd = os.open(path, os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW | os.O_CLOEXEC)
        except OSError as e:
            if e.errno in (errno.ELOOP, errno.ENOTDIR) and os.path.islink(path):
                raise UsageError(
                    f"{path!r} is a symlink; name the folder it points to (links are not followed)"
                ) from None
            raise UsageError(f"cannot write into {path!r}: {e.strerror or e}") from None
        folder = cls(path, fd)
        try:
            if made:
                os.fchmod(fd, FOLDER_MODE)  # whatever the umask
            folder._check(force=force)
        except BaseException:
            folder.close()
            raise
        return folder

    def _check(self, *, force: bool) -> None:
        st = os.fstat(self.fd)
        me = os.geteuid()
        if st.st_uid != me:
            raise UsageError(
                f"{self.path!r} belongs to {_user(st.st_uid)}, not to you ({_user(me)}): they"
                " could change the units before they are installed; export into a folder of"
                " your own"
            )
        if others_can_write(st):
            raise UsageError(
                f"{self.path!r} has mode {stat.S_IMODE(st.st_mode):o}: others can write into"
                " it and change the units before they are installed; chmod go-w it or export"
                " into a folder only you can write"
            )
        if os.listdir(self.fd) and not force:
            raise UsageError(
                f"{self.path!r} is not empty; choose an empty directory or pass --force"
            )

    def subfolder(self, name: str, mode: int = PRIVATE_FOLDER_MODE) -> Folder:
        """The folder ``name`` in this one, made or replaced when it is not a folder of the
        user's own, with ``mode``."""
        try:
            st = os.stat(name, dir_fd=self.fd, follow_symlinks=False)
            if not stat.S_ISDIR(st.st_mode) or st.st_uid != os.geteuid():
                self._remove(name)
        except FileNotFoundError:
            pass
        try:
            os.mkdir(name, mode, dir_fd=self.fd)
        except FileExistsError:
            pass
        fd = os.open(name, os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW, dir_fd=self.fd)
        os.fchmod(fd, mode)
        return Folder(os.path.join(self.path, name), fd)

    def write(self, name: str, data: bytes, mode: int) -> None:
        """Write the file ``name`` afresh with ``mode``: what stood there is removed first, so a
        symlink or a hard link planted at the name is never written through."""
        self._remove(name)
        flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW | os.O_CLOEXEC
        fd = os.open(name, flags, mode, dir_fd=self.fd)
        with open(fd, "wb") as f:
            os.fchmod(fd, mode)  # whatever the umask
            f.write(data)

    def _remove(self, name: str) -> None:
        try:
            st = os.stat(name, dir_fd=self.fd, follow_symlinks=False)
        except FileNotFoundError:
            return
        if stat.S_ISDIR(st.st_mode):
            import shutil

            shutil.rmtree(os.path.join(self.path, name))
        else:
            os.unlink(name, dir_fd=self.fd)

    def close(self) -> None:
        if self.fd >= 0:
            os.close(self.fd)
            self.fd = -1


def _make_parents(folder: str) -> None:
    """Make ``folder`` and what is missing above it 0755 whatever the umask (os.makedirs
    gives the folders above the umask's mode: 0777 under umask 000)."""
    if os.path.isdir(folder):
        return
    _make_parents(os.path.dirname(folder))
    try:
        os.mkdir(folder, FOLDER_MODE)
    except FileExistsError:
        return
    os.chmod(folder, FOLDER_MODE)
