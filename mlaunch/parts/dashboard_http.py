"""The launch panel's HTTP side: the page, its event streams and its controls.

Every request must be addressed to 127.0.0.1 or localhost at the port the browser used (the
panel's own, or the viewer's that passed the request on): a web page elsewhere that points a
name of its own at 127.0.0.1 (DNS rebinding) is refused (421). A control is a POST from the
page itself: an ``Origin`` of that same address, a small JSON body, and the run's token in
``X-Mlaunch-Token`` (the page gets it from the server; another site can neither read the page
nor send the header without the browser asking first, which this server never allows). What a
browser can ask is the control layer's (list, stop, start, restart, mute, unmute, logs), by a
label of the run; no request names a file or a command.

    GET  /launch/                  the page (with the token)
    GET  /launch/events[?follow=LABEL&lines=N]
                                   server-sent events: ``state`` once a second; with ``follow``,
                                   ``lines`` too: LABEL's last N lines, then each new one
    POST /launch/control           {"op": ..., "label": ...}: the control layer's answer
    POST /launch/evidence          the evidence bundle of the run so far (.tar.gz): what
                                   ``mlaunch test`` keeps of a failure, without a verdict

One stream per page (a browser opens at most six connections to a server, and a page's log view
would otherwise take a second); the page closes it while it is hidden.
"""

from __future__ import annotations

import json
import os
import socket
import socketserver
import struct
import threading
import time
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import Any
from urllib.parse import parse_qs

from mlaunch.parts.control import OPERATIONS
from mlaunch.parts.dashboard_hub import MAX_STREAMS
from mlaunch.standins.viewer_http import QuietErrors

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING
if TYPE_CHECKING:
    from typing import Protocol

    from mlaunch.parts.dashboard_hub import Hub

    class Panel(Protocol):
        """What the HTTP side uses of the launch panel (mlaunch.parts.dashboard's Dashboard is
        one): the shared state, the run's token and id, a control request, a log view's start,
        the evidence bundle."""

        @property
        def hub(self) -> Hub: ...

        @property
        def token(self) -> str: ...

        @property
        def run_id(self) -> str: ...

        def request(self, request: dict[str, object], timeout: float) -> dict[str, object]: ...

        def follow_start(self, label: str, lines: int) -> dict[str, object]: ...

        def evidence_bundle(self) -> tuple[bytes | None, str]: ...


PAGE = Path(__file__).with_name("dashboard.html")
LOCAL_NAMES = ("127.0.0.1", "localhost")
FRONT_HEADER = "X-Mlaunch-Front"
TOKEN_HEADER = "X-Mlaunch-Token"
# A browser whose socket takes nothing for this long is dropped (its thread ends).
WRITE_TIMEOUT = 10.0
KEEPALIVE = 15.0  # seconds between comments on a quiet stream (proxies and browsers keep it)
FOLLOW_PERIOD = 0.2  # how often a log view looks for new lines
MAX_BODY = 1024
MAX_LINES = 5000  # lines a log view starts with, at most
# What the page may ask of the control layer: every operation of ``mlaunch ctl``.
PAGE_OPERATIONS = OPERATIONS
CONTROL_TIMEOUT = 120.0  # a stop waits for the process's whole stop ladder


def _page(token: str) -> bytes:
    return PAGE.read_bytes().replace(b"__MLAUNCH_TOKEN__", token.encode())


def make_handler(dashboard: Panel) -> type[BaseHTTPRequestHandler]:
    page = _page(dashboard.token)
    hub = dashboard.hub

    class Handler(BaseHTTPRequestHandler):
        timeout = WRITE_TIMEOUT
        server_version = "mlaunch"

        # --- who may ask ---------------------------------------------------------------

        def port(self) -> int | None:
            """The port the browser used: this server's, or the viewer's that passed it on."""
            if isinstance(self.server, UnixPanelServer):
                front = (self.headers.get(FRONT_HEADER) or "").strip()
                return int(front) if front.isdigit() and 0 < int(front) < 65536 else None
            address = self.server.server_address
            return address[1] if isinstance(address, tuple) else None

        def origins(self) -> set[str]:
            port = self.port()
            return set() if port is None else {f"{name}:{port}" for name in LOCAL_NAMES}

        def host_allowed(self) -> bool:
            host = (self.headers.get("Host") or "").strip().lower()
            if host in self.origins():
                return True
            self._text(421, "this server answers 127.0.0.1 only\n")
            return False

        def post_allowed(self) -> bool:
            origin = (self.headers.get("Origin") or "").lower()
            if not origin.startswith("http://") or origin[7:] not in self.origins():
                self._text(403, "controls are taken only from the launch panel's own page\n")
                return False
            token = self.headers.get(TOKEN_HEADER) or ""
            if not secrets_equal(token, dashboard.token):
                self._text(403, f"a control needs this run's token ({TOKEN_HEADER})\n")
                return False
            return True

        # --- requests ------------------------------------------------------------------

        def do_GET(self) -> None:
            if not self.host_allowed():
                return
            path, _, query = self.path.partition("?")
            if path in ("/", "/launch") and not isinstance(self.server, UnixPanelServer):
                self.send_response(302)
                self.send_header("Location", "/launch/")
                self.send_header("Content-Length", "0")
                self.end_headers()
            elif path in ("/launch/", "/launch/index.html"):
                self._send(200, "text/html; charset=utf-8", page)
            elif path == "/launch/events":
                self._events(parse_qs(query))
            else:
                self._text(404, "not found: try /launch/\n")

        def do_POST(self) -> None:
            if not self.host_allowed():
                return
            path = self.path.partition("?")[0]
            if path not in ("/launch/control", "/launch/evidence"):
                self._text(404, "not found: controls are POST /launch/control\n")
                return
            if not self.post_allowed():
                return
            if path == "/launch/evidence":
                self._evidence()
                return
            request = self._body()
            if request is None:
                return
            if request.get("op") not in PAGE_OPERATIONS:
                valid = ", ".join(PAGE_OPERATIONS)
                self._json(400, {"ok": False, "error": f"op {request.get('op')!r}; valid: {valid}"})
                return
            answer = dashboard.request(request, CONTROL_TIMEOUT)
            status = 200 if answer.get("ok") else (400 if answer.get("status") == 2 else 409)
            self._json(status, answer)

        def _evidence(self) -> None:
            """The bundle as a download; the request's body (none is needed) is not read."""
            self.close_connection = True  # an unread body must not be taken for a request
            data, error = dashboard.evidence_bundle()
            if data is None:
                self._json(409, {"ok": False, "error": error})
                return
            name = f"mlaunch-evidence-{dashboard.run_id}.tar.gz"
            self.send_response(200)
            self.send_header("Content-Type", "application/gzip")
            self.send_header("Content-Length", str(len(data)))
            self.send_header("Content-Disposition", f'attachment; filename="{name}"')
            self.send_header("Cache-Control", "no-store")
            self.send_header("X-Content-Type-Options", "nosniff")
            self.end_headers()
            self.wfile.write(data)

        def _body(self) -> dict[str, Any] | None:
            kind = (self.headers.get("Content-Type") or "").split(";")[0].strip().lower()
            try:
                length = int(self.headers.get("Content-Length") or "-1")
            except ValueError:
                length = -1
            if kind != "application/json" or not 0 <= length <= MAX_BODY:
                self._text(400, f"expected a JSON body of at most {MAX_BODY} bytes\n")
                return None
            try:
                body = json.loads(self.rfile.read(length))
            except ValueError:
                body = None
            if not isinstance(body, dict):
                self._text(400, 'expected {"op": ..., "label": ...}\n')
                return None
            return body

        # --- streams -------------------------------------------------------------------

        def _stream(self, body: Any) -> None:
            """Serve one event stream, if fewer than MAX_STREAMS are open."""
            with hub.lock:
                if hub.streams >= MAX_STREAMS:
                    full = True
                else:
                    full = False
                    hub.streams += 1
                    hub.looked = True
            if full:
                self._text(503, f"at most {MAX_STREAMS} pages at once\n")
                return
            try:
                self.send_response(200)
                self.send_header("Content-Type", "text/event-stream")
                self.send_header("Cache-Control", "no-store")
                self.end_headers()
                body()
            finally:
                with hub.lock:
                    hub.streams -= 1

        def _event(self, name: str, data: bytes) -> None:
            self.wfile.write(b"event: " + name.encode() + b"\ndata: " + data + b"\n\n")
            self.wfile.flush()

        def _events(self, query: dict[str, list[str]]) -> None:
            """The state stream, and LABEL's lines with ``follow=LABEL``."""
            label = (query.get("follow") or [""])[0]
            start: dict[str, Any] | None = None
            if label:
                try:
                    lines = min(MAX_LINES, max(0, int((query.get("lines") or ["200"])[0])))
                except ValueError:
                    self._text(400, "expected ?follow=LABEL&lines=N (N: 0 or more)\n")
                    return
                start = dashboard.follow_start(label, lines)
                if not start.get("ok"):
                    self._json(404, start)
                    return
            self._stream(lambda: self._send_events(start))

        def _send_events(self, start: dict[str, Any] | None) -> None:
            """Each new state as it comes (only the latest: a slow page skips some), and the
            followed label's new lines a few times a second."""
            label, number = "", 0
            if start is not None:
                label, number = start["label"], start["next"]
                first = {"label": label, "lines": start["lines"], "skipped": 0}
                self._event("lines", json.dumps(first).encode())
            seen, quiet_since = -1, time.monotonic()
            while True:
                with hub.changed:
                    if hub.version == seen and not hub.closed:
                        hub.changed.wait(FOLLOW_PERIOD if label else KEEPALIVE)
                    if hub.closed:
                        return
                    version, state = hub.version, hub.state
                wrote = False
                if version != seen:
                    seen = version
                    self._event("state", state)
                    wrote = True
                if label:
                    skipped, new, number = hub.lines_since(label, number)
                    if new or skipped:
                        message = {"label": label, "lines": new, "skipped": skipped}
                        self._event("lines", json.dumps(message).encode())
                        wrote = True
                if wrote:
                    quiet_since = time.monotonic()
                elif time.monotonic() - quiet_since > KEEPALIVE:
                    self.wfile.write(b": still here\n\n")
                    self.wfile.flush()
                    quiet_since = time.monotonic()

        # --- answers -------------------------------------------------------------------

        def _json(self, status: int, payload: dict[str, Any]) -> None:
            self._send(status, "application/json", json.dumps(payload).encode())

        def _text(self, status: int, text: str) -> None:
            self._send(status, "text/plain; charset=utf-8", text.encode())

        def _send(self, status: int, kind: str, body: bytes) -> None:
            self.send_response(status)
            self.send_header("Content-Type", kind)
            self.send_header("Content-Length", str(len(body)))
            self.send_header("Cache-Control", "no-store")
            self.send_header("X-Content-Type-Options", "nosniff")
            self.send_header("X-Frame-Options", "SAMEORIGIN")
            self.end_headers()
            self.wfile.write(body)

        def log_message(self, format: str, *args: Any) -> None:
            pass  # every request would be a line in the launch output

    return Handler


def secrets_equal(given: str, token: str) -> bool:
    import hmac

    return hmac.compare_digest(given.encode(), token.encode())


class PanelServer(QuietErrors, ThreadingHTTPServer):
    """The panel on a port of its own (--dashboard)."""

    daemon_threads = True
    name = "dashboard"


class UnixPanelServer(QuietErrors, socketserver.ThreadingMixIn, socketserver.UnixStreamServer):
    """The panel behind the viewer's page: an abstract unix socket, this user's processes only."""

    daemon_threads = True
    name = "dashboard"

    def verify_request(self, request: Any, client_address: Any) -> bool:
        creds = request.getsockopt(socket.SOL_SOCKET, socket.SO_PEERCRED, struct.calcsize("3i"))
        _, uid, _ = struct.unpack("3i", creds)
        return bool(uid == os.getuid())


def _run(server: socketserver.BaseServer, name: str) -> None:
    thread = threading.Thread(
        target=server.serve_forever, kwargs={"poll_interval": 0.1}, name=name, daemon=True
    )
    thread.start()


def serve_tcp(dashboard: Panel, port: int) -> PanelServer:
    """The panel on 127.0.0.1:port (0: any free port), served from a thread."""
    server = PanelServer(("127.0.0.1", port), make_handler(dashboard))
    _run(server, "mlaunch-dashboard")
    return server


def serve_unix(dashboard: Panel, address: str) -> UnixPanelServer:
    """The panel at the abstract unix socket ``address``, for the viewer's page."""
    server = UnixPanelServer(address, make_handler(dashboard))
    _run(server, "mlaunch-dashboard-viewer")
    return server
