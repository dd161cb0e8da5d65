"""Keys typed on the controlling terminal, read in the supervisor's loop (for ``--status``).

The terminal (fd 0) is put in cbreak mode: no line editing and no echo, so each key arrives at
once, but ISIG stays on, so Ctrl-C, Ctrl-\\ and Ctrl-Z keep their meaning (the terminal sends
the signal; mlaunch's usual shutdown follows). Reads never block: VMIN=0/VTIME=0 make the
terminal itself non-blocking, so O_NONBLOCK is never set on a file description the shell
shares. fd 0 sits in the loop's selector; each readable turn is decoded into key names
(``"up"``, ``"down"``, ``"esc"``, ``"enter"``, or the character typed) for ``on_key``.

The terminal's settings are put back on every way out: ``close`` (the status view's, in the
pipeline's ``finally``, so exceptions too), an ``atexit`` fallback should a close be skipped,
and, when mlaunch is killed outright (SIGKILL, OOM), the guard (mlaunch.engine.guard), which was
told the settings to put back. Only the terminal's foreground process group may change or read
it (a background one would be stopped by SIGTTOU/SIGTTIN): in the background the keys are not
read, and they are taken up again once mlaunch is in the foreground (``check``, called from the
status view's refresh).
"""

from __future__ import annotations

import atexit
import os
import selectors
import signal
import termios
from collections.abc import Callable

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

# Escape sequences of the keys the status view knows; any other sequence is read and ignored.
SEQUENCES = {
    b"\x1b[A": "up",
    b"\x1bOA": "up",
    b"\x1b[B": "down",
    b"\x1bOB": "down",
    b"\x1b[C": "right",
    b"\x1bOC": "right",
    b"\x1b[D": "left",
    b"\x1bOD": "left",
    b"\x1b[5~": "pgup",
    b"\x1b[6~": "pgdn",
    b"\x1b[H": "home",
    b"\x1b[F": "end",
}
CONTROL = {b"\r": "enter", b"\n": "enter", b"\x7f": "backspace", b"\t": "tab"}


def decode(data: bytes) -> tuple[list[str], bytes]:
    """(key names in ``data``, an incomplete escape sequence left at its end).

    A lone ESC ends the data it came in (terminals write a key's whole sequence at once), so
    it is the Esc key; ``ESC [`` or ``ESC O`` with its final byte still to come is kept for
    the next read.
    """
    keys: list[str] = []
    i, n = 0, len(data)
    while i < n:
        byte = data[i : i + 1]
        if byte != b"\x1b":
            end = _char_end(data, i)
            if end > n:
                return keys, data[i:]  # a UTF-8 character cut by the read
            text = data[i:end]
            i = end
            if text in CONTROL:
                keys.append(CONTROL[text])
            else:
                char = text.decode("utf-8", "replace")
                if char.isprintable():
                    keys.append(char)
            continue
        if i + 1 == n:
            keys.append("esc")
            break
        kind = data[i + 1 : i + 2]
        if kind not in (b"[", b"O"):
            keys.append("esc")  # Esc typed just before another key (or Alt+key): Esc first
            i += 1
            continue
        end = i + 2
        if kind == b"[":
            # A CSI sequence: parameter bytes (0x20-0x3F), then one final byte (0x40-0x7E).
            while end < n and 0x20 <= data[end] <= 0x3F:
                end += 1
        if end >= n:
            return keys, data[i:]
        sequence = data[i : end + 1]
        if sequence in SEQUENCES:
            keys.append(SEQUENCES[sequence])
        i = end + 1
    return keys, b""


def _char_end(data: bytes, i: int) -> int:
    """Where the UTF-8 character starting at ``data[i]`` ends (beyond ``len(data)``: cut)."""
    lead = data[i]
    if lead < 0xC0:
        return i + 1
    return i + (2 if lead < 0xE0 else 3 if lead < 0xF0 else 4)


def guard_line(attrs: list[Any]) -> bytes:
    """The terminal settings to put back, as one line for the guard (``t`` + the fields)."""
    iflag, oflag, cflag, lflag, ispeed, ospeed, cc = attrs
    chars = b"".join(c if isinstance(c, bytes) else bytes([c]) for c in cc)
    return b"t %d %d %d %d %d %d %s\n" % (
        iflag,
        oflag,
        cflag,
        lflag,
        ispeed,
        ospeed,
        chars.hex().encode(),
    )


def parse_guard_line(line: bytes) -> list[Any] | None:
    """The settings a ``guard_line`` carries (None for ``t`` alone: nothing to put back)."""
    fields = line.split()[1:]
    if len(fields) != 7:
        return None
    numbers = [int(f) for f in fields[:6]]
    chars = bytes.fromhex(fields[6].decode())
    return [*numbers, [chars[k : k + 1] for k in range(len(chars))]]


class Keyboard:
    """Cbreak mode on terminal ``fd`` for the life of a run, its keys read in the loop.

    ``on_key(name)`` is called from the supervisor's loop for each key. ``tell_guard(line)``
    hands the guard the settings to put back should mlaunch be killed (``b"t\\n"``: nothing).
    Start with ``start``; ``close`` puts everything back (safe to call more than once).
    """

    def __init__(
        self,
        selector: selectors.BaseSelector,
        on_key: Callable[[str], None],
        *,
        fd: int = 0,
        tell_guard: Callable[[bytes], None] | None = None,
    ) -> None:
        self.selector = selector
        self.on_key = on_key
        self.fd = fd
        self.tell_guard = tell_guard
        self.saved: list[Any] | None = None  # the settings found at start: what is put back
        self.reading = False
        self.closed = False
        self._partial = b""

    def foreground(self) -> bool:
        """mlaunch's process group owns the terminal (it may read it and change its mode)."""
        try:
            return os.tcgetpgrp(self.fd) == os.getpgrp()
        except OSError:
            return False

    def start(self) -> bool:
        """Cbreak mode and reading; False (nothing changed) when mlaunch is in the background."""
        if self.closed or not self.foreground():
            return False
        try:
            saved = termios.tcgetattr(self.fd)
        except termios.error:
            return False
        if self.saved is None:
            self.saved = saved
            atexit.register(self.close)
            if self.tell_guard is not None:
                self.tell_guard(guard_line(saved))
        self._set_cbreak(saved)
        self._read_from_loop(True)
        return True

    def _set_cbreak(self, attrs: list[Any]) -> None:
        mode = list(attrs)
        mode[3] = mode[3] & ~(termios.ICANON | termios.ECHO)  # ISIG stays: Ctrl-C is Ctrl-C
        cc = list(mode[6])
        cc[termios.VMIN] = 0  # read returns what is there, at once: never blocks
        cc[termios.VTIME] = 0
        mode[6] = cc
        _set_attrs(self.fd, mode)

    def _read_from_loop(self, on: bool) -> None:
        if on == self.reading:
            return
        try:
            if on:
                self.selector.register(self.fd, selectors.EVENT_READ, self._readable)
            else:
                self.selector.unregister(self.fd)
        except (KeyError, ValueError, OSError):
            pass  # the selector is closed (the run ended) or never had it
        self.reading = on

    def check(self) -> None:
        """Follow job control: stop reading in the background, take up again in the foreground
        (the shell may have put its own mode back while mlaunch was stopped by Ctrl-Z)."""
        if self.closed:
            return
        if self.saved is None:
            self.start()  # mlaunch was started in the background
            return
        if not self.foreground():
            self._read_from_loop(False)
            return
        try:
            current = termios.tcgetattr(self.fd)
        except termios.error:
            return
        if current[3] & termios.ICANON or not self.reading:
            self._set_cbreak(current)
            self._read_from_loop(True)

    def _readable(self, fd: int) -> None:
        if not self.foreground():
            self._read_from_loop(False)  # moved to the background: a read would stop us
            return
        try:
            data = os.read(fd, 1024)
        except OSError:
            data = b""
        if not data:
            # Readable yet nothing to read: the terminal hung up (SIGHUP is on its way).
            # Selecting it again would spin the loop for as long as the shutdown takes.
            self._read_from_loop(False)
            return
        keys, self._partial = decode(self._partial + data)
        for key in keys:
            self.on_key(key)

    def close(self) -> None:
        """Stop reading and put the terminal's settings back (idempotent)."""
        if self.closed:
            return
        self.closed = True
        self._read_from_loop(False)
        if self.saved is None:
            return
        atexit.unregister(self.close)
        try:
            _set_attrs(self.fd, self.saved)
        except termios.error:
            pass  # the terminal is gone: nothing to put back
        if self.tell_guard is not None:
            self.tell_guard(b"t\n")


def _set_attrs(fd: int, attrs: list[Any]) -> None:
    """tcsetattr that works from the background too: SIGTTOU would stop mlaunch there."""
    old = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGTTOU})
    try:
        termios.tcsetattr(fd, termios.TCSANOW, attrs)
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)
