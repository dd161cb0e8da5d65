"""The viewer stand-in's web server: the page, its JSON state and the depth picture.

Only the standard library (http.server in a thread). A browser that goes away mid-request is
routine and costs no traceback in the launch output.
"""

from __future__ import annotations

import json
import os
import sys
import threading
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import TYPE_CHECKING, Any

from mlaunch.standins.viewer_config import PORT_ENV, ViewerError

if TYPE_CHECKING:
    from mlaunch.standins.viewer import ViewerState

PAGE = Path(__file__).with_name("viewer.html")


def make_handler(state: ViewerState, page: bytes, clock: Any) -> type[BaseHTTPRequestHandler]:
    """A request handler class serving the page and its JSON for this ``state``."""

    class Handler(BaseHTTPRequestHandler):
        def do_GET(self) -> None:
            path = self.path.split("?", 1)[0]
            if path in ("/", "/index.html"):
                self._send(200, "text/html; charset=utf-8", page)
            elif path == "/state.json":
                state.note_poll(clock())
                body = json.dumps(state.snapshot(clock()), separators=(",", ":")).encode()
                self._send(200, "application/json", body)
            elif path == "/depth.png" and (png := state.depth_png()) is not None:
                self._send(200, "image/png", png)
            else:
                self._send(404, "text/plain; charset=utf-8", b"not found: try /\n")

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


# A browser that goes away mid-request (a reload, a cancelled poll, a closed tab) is routine.
BROWSER_GONE = (BrokenPipeError, ConnectionResetError, ConnectionAbortedError, TimeoutError)


class PageServer(ThreadingHTTPServer):
    """The page's HTTP server: a browser that resets its connection is not an error.

    socketserver prints a 20-line traceback into the launch output for every failed request;
    here a reset is counted (``gone``) and anything else is one line on stderr, written in one
    call so that concurrent requests do not interleave.
    """

    daemon_threads = True
    gone = 0

    def handle_error(self, request: Any, client_address: Any) -> None:
        error = sys.exc_info()[1]
        if isinstance(error, BROWSER_GONE):
            self.gone += 1
            return
        try:
            where = f"{client_address[0]}:{client_address[1]}"
        except (TypeError, IndexError):
            where = str(client_address)
        line = f"viewer: a request from {where} failed: {type(error).__name__}: {error}\n"
        try:
            os.write(2, line.encode("utf-8", "replace"))
        except OSError:
            pass


def serve(state: ViewerState, port: int, clock: Any) -> PageServer:
    """Start the page server on 127.0.0.1:port in a daemon thread and return it."""
    page = PAGE.read_bytes()
    try:
        server = PageServer(("127.0.0.1", port), make_handler(state, page, clock))
    except OSError as exc:
        raise ViewerError(
            f"cannot listen on 127.0.0.1:{port}: {exc.strerror}; valid: a free port, or 0 for"
            f" any free port (mlaunch --viewer-port, or {PORT_ENV})"
        ) from None
    threading.Thread(target=server.serve_forever, name="viewer-http", daemon=True).start()
    return server
