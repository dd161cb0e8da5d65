"""systemd's notify protocol (sd_notify(3)), spoken without a library: one datagram per message.

A service of ``Type=notify`` gets ``NOTIFY_SOCKET`` (a path, or ``@name`` for an abstract
socket); each message is ``KEY=VALUE`` lines in one AF_UNIX datagram: ``READY=1``,
``STATUS=...``, ``STOPPING=1``, ``WATCHDOG=1``. ``WATCHDOG_USEC`` (and ``WATCHDOG_PID``, when it
names this process) asks for a ``WATCHDOG=1`` at least that often.

Nothing the supervisor does may fail because systemd went away or the socket is odd: a message
that cannot be sent is dropped, and the first failure is kept in ``error`` for whoever says it.
"""

from __future__ import annotations

import os
import socket

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Mapping

# A STATUS= line longer than this is cut (systemctl status shows one line of it).
MAX_STATUS = 200


class Notifier:
    """Sends notify messages to the socket ``address`` names (NOTIFY_SOCKET's syntax)."""

    def __init__(self, address: str, watchdog_usec: int = 0) -> None:
        self.address = address
        self.watchdog_usec = watchdog_usec
        self.error = ""
        self.sent = 0
        self._sock: socket.socket | None = None

    @classmethod
    def from_environ(cls, environ: Mapping[str, str]) -> Notifier | None:
        """The notifier a supervisor asked for in ``environ``, or None (not run by one).

        A NOTIFY_SOCKET that is neither an absolute path nor ``@name`` is refused with a
        ValueError (a unit's typo would otherwise be a start that never becomes ready)."""
        address = environ.get("NOTIFY_SOCKET", "")
        if not address:
            return None
        if not (address.startswith("/") or address.startswith("@")) or "\0" in address:
            raise ValueError(
                f"NOTIFY_SOCKET={address!r}: expected an absolute socket path or @abstract-name"
            )
        return cls(address, watchdog_interval_usec(environ))

    def target(self) -> str | bytes:
        """The address as ``socket.sendto`` takes it (abstract: a leading NUL byte)."""
        if self.address.startswith("@"):
            return b"\0" + self.address[1:].encode()
        return self.address

    def send(self, *lines: str) -> bool:
        """One datagram of ``lines``; False (and ``error``) when it could not be sent."""
        text = "\n".join(_clean(line) for line in lines)
        try:
            if self._sock is None:
                self._sock = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM | socket.SOCK_CLOEXEC)
                self._sock.setblocking(False)
            self._sock.sendto(text.encode("utf-8", "replace"), self.target())
        except OSError as e:
            if not self.error:
                self.error = f"cannot notify {self.address}: {e.strerror or e}"
            return False
        self.sent += 1
        return True

    def ready(self, status: str) -> bool:
        return self.send("READY=1", f"STATUS={status}", f"MAINPID={os.getpid()}")

    def status(self, status: str) -> bool:
        return self.send(f"STATUS={status}")

    def stopping(self, status: str) -> bool:
        return self.send("STOPPING=1", f"STATUS={status}")

    def watchdog(self) -> bool:
        return self.send("WATCHDOG=1")

    def close(self) -> None:
        if self._sock is not None:
            self._sock.close()
            self._sock = None


def watchdog_interval_usec(environ: Mapping[str, str]) -> int:
    """WATCHDOG_USEC when it is for this process (WATCHDOG_PID unset or ours), else 0."""
    pid = environ.get("WATCHDOG_PID", "")
    if pid and pid != str(os.getpid()):
        return 0
    value = environ.get("WATCHDOG_USEC", "")
    return int(value) if value.isdigit() else 0


def _clean(line: str) -> str:
    """One KEY=VALUE line: no newline inside a value, STATUS= kept short."""
    line = line.replace("\n", " ").replace("\r", " ")
    return line if len(line) <= MAX_STATUS else line[: MAX_STATUS - 3] + "..."
