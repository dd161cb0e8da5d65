"""The viewer stand-in's web server: the page, its JSON state, the depth picture, and driving.

Only the standard library (http.server in a thread). A browser that goes away mid-request is
routine and costs no traceback in the launch output.

It listens on 127.0.0.1 only, and answers only requests addressed to it by that name: a
``Host:`` of ``127.0.0.1`` or ``localhost`` (with its port, if any). A web page elsewhere could
otherwise point a name of its own at 127.0.0.1 (DNS rebinding) and read ``/state.json``. A
connection that sends nothing for ``IDLE_TIMEOUT`` seconds is closed (each holds a thread).
``POST /cmd_vel`` (the page's keys) is taken only from the page itself: same Host, an
``Origin`` of this server, and a JSON body, which a cross-site form cannot send.

``/launch/...`` is the launch panel (mlaunch.parts.dashboard) of the run this viewer belongs to:
passed on, as it came, to mlaunch over an abstract unix socket named after the run id
(``MLAUNCH_RUN_ID``), and its answer passed back; mlaunch makes the same checks as for its own
port, against this server's. Without mlaunch (or without the panel) it answers 503.
"""

from __future__ import annotations

import json
import math
import os
import socket
import sys
import threading
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

from mlaunch.standins.viewer_config import PORT_ENV, RUN_ID_ENV, ViewerError, dashboard_socket

if TYPE_CHECKING:

    class PageState(Protocol):
        """What the page server reads of the viewer (mlaunch.standins.viewer's ViewerState is
        one): a page's poll noted, the state as JSON, the depth picture."""

        def note_poll(self, now: float) -> None: ...

        def snapshot(self, now: float) -> dict[str, Any]: ...

        def depth_png(self) -> bytes | None: ...


PAGE = Path(__file__).with_name("viewer.html")
IDLE_TIMEOUT = 5.0  # seconds a connection may stay silent (the page polls every 0.1 s)
LOCAL_NAMES = ("127.0.0.1", "localhost")
# The fastest the page may ask for (m/s, rad/s): a key held is a command, not a typo's 1e9.
MAX_LINEAR, MAX_ANGULAR = 2.0, 3.0
# The page sends a held key's command every 0.1 s; a motion no command renewed for this long
# (a tab closed, a lost connection, a browser that stopped) is stopped by the server itself.
DEADMAN = 0.5
DEADMAN_CHECK = 0.05  # how often the server looks: a stop comes within 0.55 s
PANEL = "/launch/"  # the launch panel's paths, passed on to mlaunch
# What of a browser's request the panel needs (the rest stays here).
PANEL_HEADERS = ("Host", "Origin", "Content-Type", "Accept", "X-Mlaunch-Token")
PANEL_BODY_MAX = 4096
PANEL_TIMEOUT = 30.0  # mlaunch's streams say something every 15 s at least


class Drive(Protocol):
    def __call__(self, linear: float, angular: float) -> None: ...


def make_handler(
    state: PageState, page: bytes, clock: Any, drive: Drive | None = None
) -> type[BaseHTTPRequestHandler]:
    """A request handler class serving the page and its JSON for this ``state``; ``drive``
    publishes the page's velocity commands (None: driving is off)."""

    class Handler(BaseHTTPRequestHandler):
        timeout = IDLE_TIMEOUT

        def origins(self) -> set[str]:
            address = self.server.server_address
            port = address[1] if isinstance(address, tuple) else 0
            return {f"{name}:{port}" for name in LOCAL_NAMES} | set(LOCAL_NAMES)

        def host_allowed(self) -> bool:
            host = (self.headers.get("Host") or "").strip().lower()
            if host in self.origins():
                return True
            self._send(421, "text/plain; charset=utf-8", b"this server answers 127.0.0.1 only\n")
            return False

        def do_POST(self) -> None:
            if not self.host_allowed():
                return
            if self.path.startswith(PANEL):
                self._panel("POST")
                return
            if self.path.split("?", 1)[0] != "/cmd_vel" or drive is None:
                self._send(404, "text/plain; charset=utf-8", b"not found: try /\n")
                return
            origin = (self.headers.get("Origin") or "").lower()
            if not origin.startswith("http://") or origin[7:] not in self.origins():
                self._send(403, "text/plain; charset=utf-8", b"only the viewer's page drives\n")
                return
            command = self._command()
            if command is None:
                return
            drive(*command)
            self._send(204, "text/plain; charset=utf-8", b"")

        def _command(self) -> tuple[float, float] | None:
            """(linear, angular) from a small JSON body, or None once the 400 is sent."""
            kind = (self.headers.get("Content-Type") or "").split(";")[0].strip().lower()
            try:
                length = int(self.headers.get("Content-Length") or "-1")
            except ValueError:
                length = -1
            if kind != "application/json" or not 0 <= length <= 1024:
                self._send(400, "text/plain; charset=utf-8", b"expected a small JSON body\n")
                return None
            try:
                body = json.loads(self.rfile.read(length))
                linear, angular = float(body["linear"]), float(body["angular"])
            except (ValueError, KeyError, TypeError):
                linear = angular = math.nan
            if not (math.isfinite(linear) and math.isfinite(angular)):
                self._send(
                    400,
                    "text/plain; charset=utf-8",
                    b'expected {"linear": m/s, "angular": rad/s}\n',
                )
                return None
            return _clamp(linear, MAX_LINEAR), _clamp(angular, MAX_ANGULAR)

        def do_GET(self) -> None:
            if not self.host_allowed():
                return
            path = self.path.split("?", 1)[0]
            if path.startswith(PANEL):
                self._panel("GET")
            elif path in ("/", "/index.html"):
                self._send(200, "text/html; charset=utf-8", page)
            elif path == "/state.json":
                state.note_poll(clock())
                body = json.dumps(state.snapshot(clock()), separators=(",", ":")).encode()
                self._send(200, "application/json", body)
            elif path == "/depth.png" and (png := state.depth_png()) is not None:
                self._send(200, "image/png", png)
            else:
                self._send(404, "text/plain; charset=utf-8", b"not found: try /\n")

        def _panel(self, method: str) -> None:
            """Pass the request on to the run's launch panel, and its answer back as it comes
            (the panel's streams too); the panel closes the connection after it."""
            length = int(self.headers.get("Content-Length") or "0") if method == "POST" else 0
            if not 0 <= length <= PANEL_BODY_MAX:
                self._send(400, "text/plain; charset=utf-8", b"too large a request\n")
                return
            body = self.rfile.read(length) if length else b""
            run_id = os.environ.get(RUN_ID_ENV, "")
            panel = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
            panel.settimeout(PANEL_TIMEOUT)
            try:
                if not run_id:
                    raise ConnectionRefusedError
                panel.connect(dashboard_socket(run_id))
            except OSError:
                panel.close()
                text = b"no launch panel: this viewer does not run under mlaunch\n"
                self._send(503, "text/plain; charset=utf-8", text)
                return
            port = (
                self.server.server_address[1]
                if isinstance(self.server.server_address, tuple)
                else 0
            )
            head = [f"{method} {self.path} HTTP/1.0", f"X-Mlaunch-Front: {port}"]
            head += [
                f"{name}: {self.headers[name]}" for name in PANEL_HEADERS if name in self.headers
            ]
            head.append(f"Content-Length: {len(body)}")
            with panel:
                panel.sendall(("\r\n".join(head) + "\r\n\r\n").encode("latin-1") + body)
                self.close_connection = True
                while chunk := panel.recv(65536):
                    self.wfile.write(chunk)
                    self.wfile.flush()

        def _send(self, status: int, kind: str, body: bytes) -> None:
            self.send_response(status)
            self.send_header("Content-Type", kind)
            self.send_header("Content-Length", str(len(body)))
            self.send_header("Cache-Control", "no-store")
            self.end_headers()
            self.wfile.write(body)

        def log_message(self, format: str, *args: Any) -> None:
            pass  # a poll every 100 ms would flood the launch output

    return Handler


def twist_driver(node: Any) -> Drive:
    """What the page's keys call: publish (linear m/s, angular rad/s) as a Twist on cmd_vel."""
    from geometry_msgs.msg import Twist  # the viewer's process has rclpy; this module does not

    publisher = node.create_publisher(Twist, "cmd_vel", 10)

    def drive(linear: float, angular: float) -> None:
        msg = Twist()
        msg.linear.x, msg.angular.z = linear, angular
        publisher.publish(msg)

    return drive


def _clamp(value: float, limit: float) -> float:
    return max(-limit, min(limit, value))


# A browser that goes away mid-request (a reload, a cancelled poll, a closed tab) is routine.
BROWSER_GONE = (BrokenPipeError, ConnectionResetError, ConnectionAbortedError, TimeoutError)


class QuietErrors:
    """A page server's errors: a browser that resets its connection is not an error.

    socketserver prints a 20-line traceback into the launch output for every failed request;
    here a reset is counted (``gone``) and anything else is one line on stderr, written in one
    call so that concurrent requests do not interleave, starting with ``name``. (The launch
    panel's servers, mlaunch.parts.dashboard_http, share it.)
    """

    gone = 0
    name = "viewer"

    def handle_error(self, request: Any, client_address: Any) -> None:
        error = sys.exc_info()[1]
        if isinstance(error, BROWSER_GONE):
            self.gone += 1
            return
        try:
            where = f" from {client_address[0]}:{client_address[1]}"
        except (TypeError, IndexError):
            where = f" from {client_address}" if client_address else ""
        line = f"{self.name}: a request{where} failed: {type(error).__name__}: {error}\n"
        try:
            os.write(2, line.encode("utf-8", "replace"))
        except OSError:
            pass


class PageServer(QuietErrors, ThreadingHTTPServer):
    """The page's HTTP server (QuietErrors)."""

    daemon_threads = True
    deadman: DeadMan | None = None

    def shutdown(self) -> None:
        if self.deadman is not None:
            self.deadman.stop()
        super().shutdown()


class DeadMan:
    """The page's drive commands, with a dead-man: a motion that no command renews for
    ``DEADMAN`` seconds gets a stop (0, 0), once, from the server's own thread."""

    def __init__(self, drive: Drive, clock: Any) -> None:
        self._drive = drive
        self._clock = clock
        self._lock = threading.Lock()
        self._moving_since: float | None = None  # when the last non-zero command came
        self._stopped = threading.Event()

    def __call__(self, linear: float, angular: float) -> None:
        with self._lock:
            self._moving_since = self._clock() if (linear or angular) else None
            self._drive(linear, angular)

    def check(self) -> bool:
        """Stop a motion whose command is older than DEADMAN; whether it did."""
        with self._lock:
            since = self._moving_since
            if since is None or self._clock() - since < DEADMAN:
                return False
            self._moving_since = None
            self._drive(0.0, 0.0)
            return True

    def watch(self) -> None:
        """Check every DEADMAN_CHECK seconds until stopped (a daemon thread's loop)."""
        while not self._stopped.wait(DEADMAN_CHECK):
            self.check()

    def stop(self) -> None:
        self._stopped.set()


def serve(state: PageState, port: int, clock: Any, drive: Drive | None = None) -> PageServer:
    """Start the page server on 127.0.0.1:port in a daemon thread and return it."""
    page = PAGE.read_bytes()
    deadman = None if drive is None else DeadMan(drive, clock)
    try:
        server = PageServer(("127.0.0.1", port), make_handler(state, page, clock, deadman))
    except OSError as exc:
        raise ViewerError(
            f"cannot listen on 127.0.0.1:{port}: {exc.strerror}; valid: a free port, or 0 for"
            f" any free port (mlaunch --viewer-port, or {PORT_ENV})"
        ) from None
    threading.Thread(target=server.serve_forever, name="viewer-http", daemon=True).start()
    if deadman is not None:
        server.deadman = deadman
        threading.Thread(target=deadman.watch, name="viewer-deadman", daemon=True).start()
    return server
