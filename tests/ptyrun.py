"""Run a program on a pseudo-terminal of a fixed size, type keys, and read its screen.

The program is the session leader of a new pty (its controlling terminal, so Ctrl-C typed on it
is the terminal's SIGINT and the program is the foreground process group). What it writes is
fed to pyte, a terminal emulator, so tests see the screen as a person would: the lines now on
it (``display``) and everything that scrolled by (``history``). Every wait has a deadline
(procutil.wait_for); the test keeps a handle on the pty's slave side to read the terminal's
settings (cbreak or not) as the program left them.
"""

from __future__ import annotations

import fcntl
import os
import select
import signal
import struct
import termios
import time
from collections.abc import Sequence

import pyte
from procutil import wait_for


class PtyRun:
    """``argv`` on a ``columns`` x ``lines`` pty, with ``env``."""

    def __init__(
        self,
        argv: Sequence[str],
        *,
        env: dict[str, str],
        columns: int = 120,
        lines: int = 30,
        cwd: str | None = None,
    ) -> None:
        self.master, self.slave = os.openpty()
        fcntl.ioctl(self.master, termios.TIOCSWINSZ, struct.pack("HHHH", lines, columns, 0, 0))
        self.screen = pyte.HistoryScreen(columns, lines, history=5000)
        self.stream = pyte.ByteStream(self.screen)
        self.raw = bytearray()
        self.returncode: int | None = None
        pid = os.fork()
        if pid == 0:  # the child: only system calls until exec
            try:
                os.setsid()
                fcntl.ioctl(self.slave, termios.TIOCSCTTY, 0)
                for fd in (0, 1, 2):
                    os.dup2(self.slave, fd)
                os.closerange(3, 1 << 12)
                if cwd:
                    os.chdir(cwd)
                os.execve(argv[0], list(argv), env)
            finally:
                os._exit(127)
        self.pid = pid
        os.set_blocking(self.master, False)

    # --- reading the screen ----------------------------------------------------------------

    def pump(self, timeout: float = 0.05) -> None:
        """Feed the emulator what the program wrote (waiting up to ``timeout`` for some)."""
        if self.master < 0:
            select.select([], [], [], timeout)  # hung up: only the wait
            return
        ready, _, _ = select.select([self.master], [], [], timeout)
        while ready:
            try:
                data = os.read(self.master, 65536)
            except (BlockingIOError, OSError):
                break
            if not data:
                break
            self.raw += data
            self.stream.feed(data)
            ready, _, _ = select.select([self.master], [], [], 0)

    def now(self) -> str:
        """The screen's text after reading what is there (not waiting for more)."""
        self.pump(0)
        return self.text()

    def display(self) -> list[str]:
        """The lines on the screen now, right-stripped."""
        return [line.rstrip() for line in self.screen.display]

    def text(self) -> str:
        return "\n".join(self.display())

    def history(self) -> str:
        """Everything that scrolled off the top, then the screen: the whole session's text."""
        scrolled = [
            "".join(line[x].data for x in sorted(line)).rstrip() for line in self.screen.history.top
        ]
        return "\n".join([*scrolled, *self.display()])

    def wait_screen(self, predicate: object, timeout: float = 15.0, what: str = "") -> str:
        """Until ``predicate(screen text)`` holds (or the text contains it, for a str)."""

        def check() -> str | None:
            self.pump()
            text = self.text()
            ok = predicate(text) if callable(predicate) else str(predicate) in text
            return text if ok else None

        try:
            return wait_for(check, timeout, what or repr(predicate), interval=0.0)
        except AssertionError as e:
            raise AssertionError(f"{e}; the screen:\n{self.text()}") from None

    # --- typing and the terminal ---------------------------------------------------------------

    def type(self, keys: bytes) -> None:
        os.write(self.master, keys)

    def modes(self) -> int:
        """The terminal's local modes (ICANON, ECHO, ISIG ...) as the program set them."""
        return int(termios.tcgetattr(self.slave)[3])

    def cooked(self) -> bool:
        """Line editing and echo on: the terminal as a shell expects it."""
        modes = self.modes()
        return bool(modes & termios.ICANON and modes & termios.ECHO)

    def hang_up(self) -> None:
        """Close the terminal's window: the program's session gets SIGHUP, reads get nothing."""
        os.close(self.master)
        self.master = -1

    # --- the end -----------------------------------------------------------------------------

    def poll(self) -> int | None:
        if self.returncode is None:
            pid, status = os.waitpid(self.pid, os.WNOHANG)
            if pid:
                self.returncode = os.waitstatus_to_exitcode(status)
        return self.returncode

    def wait(self, timeout: float = 20.0) -> int:
        """Until the program exits, reading its screen meanwhile; its exit status."""

        def done() -> bool:
            self.pump()
            return self.poll() is not None

        try:
            wait_for(done, timeout, "the program to exit", interval=0.0)
        except AssertionError as e:
            raise AssertionError(f"{e}; the screen:\n{self.text()}") from None
        self.pump(0)
        assert self.returncode is not None
        return self.returncode

    def kill(self) -> None:
        if self.poll() is None:
            try:
                os.killpg(self.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
            deadline = time.monotonic() + 5
            while self.poll() is None and time.monotonic() < deadline:
                self.pump()

    def close(self) -> None:
        self.kill()
        for fd in (self.master, self.slave):
            if fd < 0:
                continue
            try:
                os.close(fd)
            except OSError:
                pass
