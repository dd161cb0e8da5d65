"""The run's control socket: ``mlaunch ctl`` requests served on the supervisor's own loop.

An AF_UNIX stream socket at ``<run log folder>/control/ctl.sock``: the folder is 0700 and the
socket 0600, so only the user who runs mlaunch reaches it. It is opened on the loop's first turn
(after the first children started: ``socket`` costs milliseconds; ``json`` waits for the first
request) and registered in the loop's selector, so every request is read and carried out on the
loop thread, by mlaunch.parts.control, never racing the supervisor. It is removed when the run
ends; if mlaunch is killed, its guard removes it (mlaunch.engine.guard); a socket left behind
anyway is found stale by ``mlaunch ctl`` (nobody accepts), never waited on.

The protocol is JSON lines. A request is one line: ``{"op": "stop", "label": "talker"}`` (op:
one of mlaunch.parts.control.OPERATIONS, or ``ready`` with no label: the run's readiness
checks; ``lines`` for logs). The answer is one line with ``ok``;
a stop or restart first sends ``{"accepted": true, "wait": SECONDS}`` (how long its stop ladder
may take), then the answer once the process has exited (or started again). Every answer carries
``run`` (pid, run id, log folder). A failed request answers ``ok: false`` with ``error`` (one
line), ``status`` (errors' exit-status table) and, for an unknown label, ``labels`` and
``close``.

Nothing a client sends stops or stalls the run: a request is bounded in size (MAX_REQUEST) and
nesting (MAX_DEPTH), every malformed one is answered with an error, a ``logs`` answer is bounded
(MAX_LOG_LINES, logfiles.TAIL_MAX_BYTES), and an error in carrying out a request is answered,
never raised into the loop. Nor does a crowd of clients (any process of the user's can connect,
the launch's own children too): at most MAX_CLIENTS are held, the one idle longest making room
for a new one; a client that sends no whole request within REQUEST_TIMEOUT, or reads nothing of
its answer within SEND_TIMEOUT, is closed; answers nobody reads hold at most MAX_QUEUED bytes in
all (a ``logs`` answer past it is refused: try again); and when the descriptors run short
(EMFILE, or a new connection's number within RESERVE_FDS of the limit) mlaunch stops accepting
for a moment instead of spinning on the error, so the supervisor keeps descriptors to respawn.
"""

from __future__ import annotations

import errno
import os
import resource
import selectors
import socket
import time
from collections.abc import Callable, Mapping

from mlaunch.plan.errors import EXIT_FAILURE, EXIT_USAGE
from mlaunch.plan.records import Said

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Protocol

    from mlaunch.engine.guard import Guard
    from mlaunch.engine.part import AttachedRun

    class SocketRun(AttachedRun, Protocol):
        """What the control socket uses of the run (the Supervisor is one): its id, and the guard
        that removes the socket after kill -9."""

        @property
        def run_id(self) -> str: ...

        @property
        def guard(self) -> Guard | None: ...

    from mlaunch.engine.timers import Timer
    from mlaunch.parts.control import Control, ProcessInfo

FOLDER = "control"
NAME = "ctl.sock"
# In FOLDER when the socket is elsewhere (the log folder takes no socket): its path.
WHERE = "where"
PROTOCOL = 1
# The request ``mlaunch ctl wait-ready`` sends (not a process operation: no label).
READY = "ready"
# A request line longer than this is refused (a request is a few dozen bytes)...
MAX_REQUEST = 4096
# ... and so is one nested deeper than this (a request is one flat object; json's parser
# recurses once per level, and a line of 60,000 '[' ran it out of stack).
MAX_DEPTH = 4
# Connections the kernel queues before mlaunch's loop accepts them (30 shells at once).
BACKLOG = 128
# ``logs``: at most this many lines per request (and logfiles.TAIL_MAX_BYTES of them).
MAX_LOG_LINES = 10_000
# Beyond a stop ladder's own timeouts, what an answer to a stop or restart may take.
WAIT_MARGIN = 5.0
# Clients held at once (30 shells at once is a crowd); a new one past it closes the idlest.
MAX_CLIENTS = 64
# A client must send its whole request within this...
REQUEST_TIMEOUT = 10.0
# ... and read some of its answer within this, or it is closed.
SEND_TIMEOUT = 30.0
# Answers queued for clients that have not read them yet, all clients together.
MAX_QUEUED = 32 * 1024 * 1024
# Descriptors kept free for the supervisor (pipes and log files of a respawn): a connection whose
# number comes this close to the soft limit is closed at once.
RESERVE_FDS = 64
# How long accepting pauses when the descriptors ran out (EMFILE): the loop must not spin on it.
ACCEPT_PAUSE = 0.5
# AF_UNIX paths longer than this (108 bytes on Linux, with the NUL) are reached through the folder.
MAX_PATH = 100


def socket_path(log_dir: str) -> str:
    """Where the control socket of the run logging to ``log_dir`` is."""
    return os.path.join(log_dir, FOLDER, NAME)


class Address:
    """An AF_UNIX address for ``path`` that fits, however long the path (a context manager).

    A long path is reached as ``/proc/self/fd/N/ctl.sock`` through an open descriptor of its
    folder (a log folder under a deep home or a test's temporary folder exceeds the limit).
    """

    def __init__(self, path: str) -> None:
        self.path = path
        self._fd = -1

    def __enter__(self) -> str:
        if len(os.fsencode(self.path)) <= MAX_PATH:
            return self.path
        folder, name = os.path.split(self.path)
        self._fd = os.open(folder, os.O_PATH | os.O_DIRECTORY)
        return f"/proc/self/fd/{self._fd}/{name}"

    def __exit__(self, *_: object) -> None:
        if self._fd >= 0:
            os.close(self._fd)
            self._fd = -1


def runtime_socket_path(log_dir: str, environ: Mapping[str, str]) -> str | None:
    """Where the socket goes when the log folder takes none: ``$XDG_RUNTIME_DIR/mlaunch/``."""
    runtime = environ.get("XDG_RUNTIME_DIR")
    if not runtime or not os.path.isdir(runtime):
        return None
    return os.path.join(runtime, "mlaunch", os.path.basename(log_dir.rstrip("/")) + ".sock")


def _listen(path: str) -> socket.socket:
    """A listening socket at ``path`` (0600) in a folder of its own made 0700."""
    folder = os.path.dirname(path)
    os.makedirs(folder, mode=0o700, exist_ok=True)
    # Made earlier with another mode: private all the same; but never through a link.
    fd = os.open(folder, os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW | os.O_CLOEXEC)
    try:
        if os.fstat(fd).st_uid != os.geteuid():
            raise PermissionError(f"{folder} is not a folder of yours")
        os.fchmod(fd, 0o700)
    finally:
        os.close(fd)
    try:
        os.unlink(path)  # a run's socket path is its own: what is there is stale
    except FileNotFoundError:
        pass
    listener = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    try:
        with Address(path) as address:
            listener.bind(address)
        os.chmod(path, 0o600)
        listener.listen(BACKLOG)
        listener.setblocking(False)
    except BaseException:
        listener.close()
        raise
    return listener


class ControlSocket:
    """The listening socket and its clients, in ``supervisor.selector``; ``close`` removes it.

    In the run's log folder; where that takes no socket (a file system without them), in
    ``$XDG_RUNTIME_DIR/mlaunch/``, named in the log folder's ``control/where``.
    """

    def __init__(
        self,
        supervisor: SocketRun,
        control: Callable[[], Control],
        log_dir: str,
        environ: Mapping[str, str] = os.environ,
        *,
        readiness: Callable[[], Callable[[], dict[str, object]] | None] = lambda: None,
    ) -> None:
        self.supervisor = supervisor
        # The run's readiness (``ready`` requests), when a part that can tell is attached.
        self.readiness = readiness
        # The run's Control, made when the first request needs it.
        self.control = control
        self.path = socket_path(log_dir)
        self.log_dir = os.path.abspath(log_dir)  # what ctl checks its answers against
        self.environ = environ
        self.error = ""  # why it could not be opened
        self._listener: socket.socket | None = None
        self._clients: list[_Client] = []
        self._paused = False  # accepting stopped for a moment: the descriptors ran out
        self._sweep: Timer | None = None

    def open(self) -> bool:
        """Bind and listen (False, with ``error``, when no folder takes the socket)."""
        listener: socket.socket | None
        try:
            listener = _listen(self.path)
        except OSError as e:
            self.error = f"cannot open the control socket {self.path}: {e.strerror or e}"
            listener = self._elsewhere()
            if listener is None:
                return False
        self._listener = listener
        self.supervisor.selector.register(listener, selectors.EVENT_READ, self._accept)
        guard = self.supervisor.guard
        if guard is not None:
            guard.remove_on_death(self.path)
        return True

    def _elsewhere(self) -> socket.socket | None:
        """The socket in the runtime folder, named in the log folder (None: no luck there)."""
        path = runtime_socket_path(self.log_dir, self.environ)
        if path is None:
            return None
        try:
            listener = _listen(path)
        except OSError as e:
            self.error += f"; nor {path}: {e.strerror or e}"
            return None
        where = os.path.join(self.log_dir, FOLDER, WHERE)
        try:
            os.makedirs(os.path.dirname(where), mode=0o700, exist_ok=True)
            fd = os.open(where, os.O_WRONLY | os.O_CREAT | os.O_TRUNC | os.O_NOFOLLOW, 0o600)
            with open(fd, "w", encoding="utf-8") as f:
                f.write(path + "\n")
        except OSError as e:
            listener.close()
            os.unlink(path)
            self.error += f"; nor can {where} name {path}: {e.strerror or e}"
            return None
        self.path = path
        return listener

    def _accept(self, fd: int) -> None:
        assert self._listener is not None
        try:
            conn, _ = self._listener.accept()
        except (BlockingIOError, InterruptedError):
            return
        except OSError as e:
            if e.errno in (errno.EMFILE, errno.ENFILE, errno.ENOBUFS, errno.ENOMEM):
                self._make_room(force=True)  # the socket stays readable: never spin on it
            return  # else the client gave up before we took it
        conn.setblocking(False)
        if conn.fileno() >= self._fd_limit() - RESERVE_FDS:
            self._refuse(conn, "mlaunch is short of file descriptors; try again")
            self._make_room(force=True)  # the supervisor's descriptors come first
            return
        if len(self._clients) >= MAX_CLIENTS:
            self._make_room(force=False)
        if len(self._clients) >= MAX_CLIENTS:  # each one waits for a stop or restart
            self._refuse(conn, f"{MAX_CLIENTS} requests are under way; try again")
            return
        client = _Client(self, conn)
        self._clients.append(client)
        self.supervisor.selector.register(conn, selectors.EVENT_READ, client.on_ready)
        if self._sweep is None:
            self._sweep = self.supervisor.schedule(1.0, self._sweep_idle, keeps_alive=False)

    def _refuse(self, conn: socket.socket, error: str) -> None:
        import json

        answer = {"ok": False, "error": error, "status": EXIT_FAILURE, "run": self.run_info()}
        try:
            conn.send(json.dumps(answer).encode() + b"\n")
        except OSError:
            pass
        _drain(conn)
        conn.close()

    def _fd_limit(self) -> int:
        soft, _hard = resource.getrlimit(resource.RLIMIT_NOFILE)
        return soft if soft != resource.RLIM_INFINITY else 1 << 20

    def _make_room(self, *, force: bool) -> None:
        """Close the client idle longest (one not waiting for a stop or restart); ``force``:
        the descriptors ran out, so also stop accepting for ACCEPT_PAUSE."""
        idle = [c for c in self._clients if c.evictable()]
        if idle:
            self.forget(min(idle, key=lambda c: c.since))
        if force and self._listener is not None and not self._paused:
            self._paused = True
            _unregister(self.supervisor.selector, self._listener)
            self.supervisor.schedule(ACCEPT_PAUSE, self._resume, keeps_alive=False)

    def _resume(self) -> None:
        self._paused = False
        if self._listener is not None:
            self.supervisor.selector.register(self._listener, selectors.EVENT_READ, self._accept)

    def _sweep_idle(self) -> None:
        """Close clients that sent no request, or read nothing, for too long (every second)."""
        self._sweep = None
        now = time.monotonic()
        for client in list(self._clients):
            if client.overdue(now):
                self.forget(client)
        if self._clients:
            self._sweep = self.supervisor.schedule(1.0, self._sweep_idle, keeps_alive=False)

    def queued(self) -> int:
        """Bytes of answers waiting for their clients to read them, all clients together."""
        return sum(len(c.out) for c in self._clients)

    def run_info(self) -> dict[str, object]:
        return {"pid": os.getpid(), "run_id": self.supervisor.run_id, "log_dir": self.log_dir}

    def forget(self, client: _Client) -> None:
        if client in self._clients:
            self._clients.remove(client)
        _unregister(self.supervisor.selector, client.conn)
        _drain(client.conn)
        client.conn.close()

    def close(self) -> None:
        """Answer who still waits (the launch ended), close, and remove the socket file."""
        for client in list(self._clients):
            client.ended()
        if self._sweep is not None:
            self._sweep.cancelled = True
            self._sweep = None
        if self._listener is not None:
            _unregister(self.supervisor.selector, self._listener)
            self._listener.close()
            self._listener = None
            for leftover in (self.path, os.path.join(self.log_dir, FOLDER, WHERE)):
                try:
                    os.unlink(leftover)
                except OSError:
                    pass
            try:
                os.rmdir(os.path.join(self.log_dir, FOLDER))
            except OSError:
                pass


def _drain(conn: socket.socket, most: int = 1024 * 1024) -> None:
    """Read what the client sent past its request (a line too long): closing a socket with
    unread input resets the connection, and the client would lose its answer."""
    try:
        conn.setblocking(False)
        while most > 0:
            data = conn.recv(65536)
            if not data:
                return
            most -= len(data)
    except OSError:
        return


def nesting(line: bytes) -> int:
    """How deep the JSON text ``line`` nests arrays and objects (brackets in strings aside)."""
    depth = deepest = 0
    in_string = escaped = False
    for byte in line:
        if in_string:
            if escaped:
                escaped = False
            elif byte == 0x5C:  # backslash
                escaped = True
            elif byte == 0x22:  # quote
                in_string = False
        elif byte == 0x22:
            in_string = True
        elif byte in (0x5B, 0x7B):  # [ {
            depth += 1
            deepest = max(deepest, depth)
        elif byte in (0x5D, 0x7D):
            depth -= 1
    return deepest


def _shown(line: bytes) -> str:
    """A request line in an error: its start, readable whatever it holds."""
    text = line[:60].decode("utf-8", "replace")
    return repr(text + ("..." if len(line) > 60 else ""))


def _unregister(selector: selectors.BaseSelector, sock: socket.socket) -> None:
    try:
        selector.unregister(sock)
    except (KeyError, ValueError, RuntimeError, OSError):
        pass  # never registered, or the loop's selector is closed already


class BadRequest(Exception):
    """A request that is JSON but not one of the protocol's (exit status 2 for the client)."""


Reply = Callable[[dict[str, object]], None]


def answer_request(
    control: Callable[[], Control],
    request: dict[str, object],
    *,
    by: str,
    answer: Reply,
    fail: Callable[..., None],
    accepted: Reply | None = None,
    shown: str = "",
) -> None:
    """Carry out one request of the protocol (``mlaunch ctl``'s, the dashboard's), on the loop
    thread: ``answer(payload)`` once it is done, or ``fail(error, status, **more)``; a stop or
    restart first says ``accepted({"accepted": True, "wait": s})``. Nothing here raises."""
    from mlaunch.parts.control import AmbiguousLabel, ControlError, UnknownLabel

    try:
        carry_out(control(), request, by=by, answer=answer, accepted=accepted, fail=fail)
    except UnknownLabel as e:
        fail(str(e), e.exit_code, labels=e.labels, close=e.close)
    except AmbiguousLabel as e:
        fail(str(e), e.exit_code, labels=e.labels)
    except ControlError as e:
        fail(str(e), e.exit_code)
    except BadRequest as e:
        fail(str(e), EXIT_USAGE)
    except Exception as e:  # an odd value this code did not foresee: said, not raised
        fail(f"the request {shown or repr(request)[:60]} failed: {type(e).__name__}: {e}")


def carry_out(
    control: Control,
    request: dict[str, object],
    *,
    by: str,
    answer: Reply,
    accepted: Reply | None = None,
    fail: Callable[..., None] | None = None,
) -> None:
    """What ``request`` asks of ``control`` (raises ControlError or BadRequest); an unload or
    load the container refused is ``fail``'s."""
    from mlaunch.parts.control import (
        COMPONENT_OPERATIONS,
        DEFAULT_LINES,
        OPERATIONS,
        TRANSITIONS,
    )

    op, label = request.get("op"), request.get("label")
    if op not in OPERATIONS:
        raise BadRequest(f"unknown operation {op!r}; valid: {', '.join(OPERATIONS)}")
    if op == "list":
        answer({"processes": [info.as_dict() for info in control.processes()]})
        return
    if not isinstance(label, str):
        raise BadRequest(f"{op} needs a process label")

    def done(info: ProcessInfo) -> None:
        answer({"process": info.as_dict()})

    if op in COMPONENT_OPERATIONS or op in TRANSITIONS:
        key = "component" if op in COMPONENT_OPERATIONS else "lifecycle"

        def answered(result: dict[str, object]) -> None:
            if result.get("error") and fail is not None:
                fail(f"{op} {result.get('name')}: {result['error']}", EXIT_FAILURE)
            else:
                answer({key: result})

        if op == "unload":
            control.unload(label, by=by, done=answered)
        elif op == "load":
            control.load(label, by=by, done=answered)
        else:
            control.transition(label, op, by=by, done=answered)
    elif op == "logs":
        lines = request.get("lines", DEFAULT_LINES)
        if not isinstance(lines, int) or isinstance(lines, bool):
            raise BadRequest(f"lines must be a whole number, not {lines!r}")
        payload: dict[str, object] = {"label": label}
        payload["lines"] = control.logs(label, min(lines, MAX_LOG_LINES))
        if lines > MAX_LOG_LINES:
            payload["limit"] = MAX_LOG_LINES
        answer(payload)
    elif op in ("mute", "unmute"):
        done(control.mute(label, by=by) if op == "mute" else control.unmute(label, by=by))
    elif op == "start":
        control.start(label, by=by, done=done)
    else:
        spec = control.process_state(label).spec  # raises before anything is said for a bad label
        if accepted is not None:
            wait = spec.sigterm_timeout + spec.sigkill_timeout + WAIT_MARGIN
            accepted({"accepted": True, "wait": wait})
        if op == "stop":
            control.stop(label, by=by, done=done)
        else:
            control.restart(label, by=by, done=done)


class _Client:
    """One connection: a request line in, JSON lines out, then closed."""

    def __init__(self, server: ControlSocket, conn: socket.socket) -> None:
        self.server = server
        self.conn = conn
        self.received = b""
        self.out = b""
        self.answered = False  # the final answer is queued: close once it is sent
        self.asked = False
        # When it connected, or last read some of its answer (the idle clock).
        self.since = time.monotonic()

    def evictable(self) -> bool:
        """Not waiting for a stop or restart under way: idle, or not reading its answer."""
        return not self.asked or self.answered

    def overdue(self, now: float) -> bool:
        if not self.asked:
            return now - self.since > REQUEST_TIMEOUT
        return bool(self.out) and now - self.since > SEND_TIMEOUT

    # --- the loop's callbacks --------------------------------------------------------------

    def on_ready(self, fd: int) -> None:
        """Readable before the request is whole; writable while an answer waits."""
        try:
            self._on_ready()
        except Exception as e:  # a bug in answering one client must not end the run
            self.answered = True
            self.out = b""
            self.server.forget(self)
            text = f"control socket: a request failed: {type(e).__name__}: {e}"
            self.server.supervisor.records.emit(Said("WARNING", "launch", text))

    def _on_ready(self) -> None:
        if self.out:
            self._send()
            return
        data = self._recv()
        if data is None:
            return
        if not data:
            self.server.forget(self)  # the client left (while its stop was under way, too)
            return
        if self.asked:
            return  # past the request: its answer comes when it is done
        self.received += data
        line, newline, _ = self.received.partition(b"\n")
        if len(line) > MAX_REQUEST:
            self.asked = True
            self.fail(f"the request is too long (more than {MAX_REQUEST} bytes)", EXIT_USAGE)
        elif newline:
            self.asked = True
            self.handle(line)

    def _recv(self) -> bytes | None:
        """What the client sent (b"" when it left), None if nothing yet."""
        try:
            return self.conn.recv(4096)
        except (BlockingIOError, InterruptedError):
            return None
        except OSError:
            return b""

    # --- the request -----------------------------------------------------------------------

    def handle(self, line: bytes) -> None:
        """Carry out one request line; whatever it holds, the client gets an answer."""
        request = self._parse(line)
        if request is None:
            return
        if request.get("op") == READY:
            self.ready()
            return
        answer_request(
            self.server.control,
            request,
            by="ctl",
            answer=self.answer,
            fail=self.fail,
            accepted=self.queue,
            shown=_shown(line),
        )

    def _parse(self, line: bytes) -> dict[str, object] | None:
        """The request as an object, or None once the error is answered."""
        depth = nesting(line)
        if depth > MAX_DEPTH:
            self.fail(f"the request is nested {depth} deep (at most {MAX_DEPTH})", EXIT_USAGE)
            return None
        try:
            import json  # at the first request, not when the socket opens

            request = json.loads(line)
        except (ValueError, RecursionError) as e:
            self.fail(f"the request {_shown(line)} is not JSON: {e}", EXIT_USAGE)
            return None
        if not isinstance(request, dict):
            self.fail(f"the request {_shown(line)} is not a JSON object", EXIT_USAGE)
            return None
        return request

    def ready(self) -> None:
        """``ready``: the readiness checks and their states (``mlaunch ctl wait-ready``)."""
        state = self.server.readiness()
        if state is None:
            self.fail("this run does not watch its readiness (mlaunch test's own checks do)")
            return
        self.answer(state())

    # --- answers ---------------------------------------------------------------------------

    def answer(self, payload: dict[str, object]) -> None:
        self.answered = True
        self.queue({"ok": True, **payload, "run": self.server.run_info()})

    def fail(self, error: str, status: int = EXIT_FAILURE, **more: object) -> None:
        self.answered = True
        self.queue(
            {"ok": False, "error": error, "status": status, **more, "run": self.server.run_info()}
        )

    def ended(self) -> None:
        """The run ended with this request unanswered: say so, as far as the socket takes it."""
        if not self.answered and self.asked:
            self.fail("the launch ended before the request was carried out")
        if self.out:
            try:
                self.conn.setblocking(True)
                self.conn.settimeout(0.5)
                self.conn.sendall(self.out)
            except OSError:
                pass
            self.out = b""
        self.server.forget(self)

    def queue(self, message: dict[str, object]) -> None:
        import json

        data = json.dumps(message).encode() + b"\n"
        self.since = time.monotonic()  # the answer's clock starts now
        waiting = self.server.queued()
        if len(data) > 4096 and waiting + len(data) > MAX_QUEUED:
            data = self._too_much(waiting)
        self.out += data
        self._send()

    def _too_much(self, waiting: int) -> bytes:
        """The failure answered instead of a large answer past MAX_QUEUED."""
        import json

        readers = sum(1 for c in self.server._clients if c.out)
        error = (
            f"{waiting // (1024 * 1024)} MiB of answers wait for {readers} clients that do not"
            f" read them (at most {MAX_QUEUED // (1024 * 1024)} MiB); try again"
        )
        failed = {"ok": False, "error": error, "status": EXIT_FAILURE}
        return json.dumps({**failed, "run": self.server.run_info()}).encode() + b"\n"

    def _send(self) -> None:
        try:
            sent = self.conn.send(self.out)
        except (BlockingIOError, InterruptedError):
            sent = 0
        except OSError:
            self.server.forget(self)  # the client went away
            return
        if sent:
            self.since = time.monotonic()
        self.out = self.out[sent:]
        if self.out:
            self.server.supervisor.selector.modify(self.conn, selectors.EVENT_WRITE, self.on_ready)
        elif self.answered:
            self.server.forget(self)
        else:
            self.server.supervisor.selector.modify(self.conn, selectors.EVENT_READ, self.on_ready)
