"""The launch panel: every process of the run, its health and output, and the controls, in a page.

Served by mlaunch itself (http.server in threads of its own), to two kinds of front:

- the viewer stand-in's page (mlaunch.standins.viewer_http), which passes every ``/launch/``
  request on to this process over an abstract unix socket named after the run id
  (``dashboard_socket``); only a process of the same user is answered there (SO_PEERCRED), and
  the front says which port the browser saw (``X-Mlaunch-Front``), so the checks below are the
  same for both fronts;
- with ``--dashboard``, a port of its own on 127.0.0.1 (``--dashboard-port``, default any free).

What a browser can do (mlaunch.parts.dashboard_http): read the page, a stream of the processes'
state (server-sent events, one message a second), the last lines of one process and what it
writes next. Every control is a same-origin POST carrying the run's token (which the page gets
from the server) and goes through mlaunch.parts.control_socket's ``answer_request`` on the
loop thread, exactly as ``mlaunch ctl``'s requests do. Nothing reads a file but through the
control layer (the process's own log file in the run's log folder), and the evidence bundle:
the same folder ``mlaunch test`` writes on a failure, built on demand from the running launch by
``evidence`` (given by the application layer, which owns the evidence writer), one at a time.

What it costs the run: the loop only hands the output lines to a bounded ring per process and
takes each second's list of processes (mlaunch.parts.metrics does, for both); each browser is
served by a thread of its own, which sends only the latest state (a slow browser skips states,
never queues them) and drops the browser once a write has been blocked for WRITE_TIMEOUT s.
"""

from __future__ import annotations

import copy
import os
import secrets
import threading
from collections import deque
from collections.abc import Callable, Mapping, Sequence
from typing import Any

from mlaunch.engine.part import Part
from mlaunch.parts.dashboard_hub import Hub
from mlaunch.plan.records import Output, Record, Said

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING
if TYPE_CHECKING:
    from socketserver import BaseServer
    from typing import Protocol

    from mlaunch.engine.part import AttachedRun
    from mlaunch.engine.process import Process

    class PanelRun(AttachedRun, Protocol):
        """What the launch panel uses of the run (the Supervisor is one): its id and its
        processes."""

        @property
        def run_id(self) -> str: ...

        @property
        def processes(self) -> list[Process]: ...

    from mlaunch.parts.control import Control
    from mlaunch.parts.handoff import LoopCall
    from mlaunch.parts.metrics import Metrics
    from mlaunch.parts.usage import Sample

# Samples of CPU and memory kept per process for the sparklines (a second each).
HISTORY = 300

# Builds the evidence bundle (a .tar.gz) from the processes as they were and their last lines.
Evidence = Callable[[Sequence[Any], Mapping[str, Sequence[str]]], bytes]


def dashboard_socket(run_id: str) -> str:
    """The abstract unix socket the run's launch panel is reached at (viewer_http's too)."""
    from mlaunch.standins.viewer_config import dashboard_socket as named

    return named(run_id)


class Dashboard(Part):
    """The launch panel's servers and state; opened on the loop's first turn.

    ``port`` None serves only the viewer's front (the abstract socket); a number also listens
    on 127.0.0.1:port (0: any free port) and says the page's address.
    """

    def __init__(
        self,
        supervisor: PanelRun,
        control: Callable[[], Control],
        metrics: Metrics,
        *,
        port: int | None,
        composable: Callable[[], list[dict[str, object]]] = lambda: [],
        evidence: Evidence | None = None,
    ) -> None:
        self.supervisor = supervisor
        self.control = control
        self.metrics = metrics
        self.port = port
        self.composable = composable  # the composable nodes and their state (any thread)
        self.evidence = evidence
        self.evidence_busy = threading.Lock()  # one bundle at a time
        self.hub = Hub()
        self.token = secrets.token_urlsafe(24)
        self.servers: list[BaseServer] = []
        self.loop: LoopCall | None = None
        self.url = ""
        supervisor.records.subscribe(self._on_record)
        metrics.listeners.append(self._sampled)
        supervisor.schedule(0.0, self._open, keeps_alive=False)

    def _open(self) -> None:
        from mlaunch.parts.dashboard_http import serve_tcp, serve_unix
        from mlaunch.parts.handoff import LoopCall

        self.loop = LoopCall(self.supervisor.selector)
        try:
            self.servers.append(serve_unix(self, dashboard_socket(self.supervisor.run_id)))
        except OSError as e:
            text = f"dashboard: the viewer's page cannot reach the launch panel: {e.strerror or e}"
            self.supervisor.records.emit(Said("WARNING", "launch", text))
        if self.port is not None:
            try:
                server = serve_tcp(self, self.port)
            except OSError as e:
                text = (
                    f"dashboard: cannot listen on 127.0.0.1:{self.port}: {e.strerror or e};"
                    " valid: a free port, or 0 for any free port (--dashboard-port)"
                )
                self.supervisor.records.emit(Said("ERROR", "launch", text))
                return
            self.servers.append(server)
            self.url = f"http://127.0.0.1:{server.server_address[1]}/launch/"
            self.supervisor.records.emit(Said("INFO", "launch", f"dashboard: open {self.url}"))

    # --- fed by the run ---------------------------------------------------------------------

    def _on_record(self, record: Record) -> None:
        if type(record) is Output:
            self.hub.add_output(record.process.label, record.data)

    def _sampled(self, sample: Sample) -> None:
        """The metrics thread: each second's state, as the message every browser gets."""
        import json

        hub = self.hub
        processes = []
        for info, usage in sample.rows:
            entry = info.as_dict()
            history = hub.history.setdefault(info.label, deque(maxlen=HISTORY))
            if usage is not None:
                history.append((round(usage.cpu, 1), usage.rss))
                entry.update(cpu=round(usage.cpu, 1), rss=usage.rss)
                entry.update(threads=usage.threads, files=usage.files)
            else:
                history.append((0.0, 0))
            entry["last"] = hub.last.get(info.label, "")
            entry["history"] = list(history)
            processes.append(entry)
        run = {"pid": os.getpid(), "run_id": self.supervisor.run_id, "elapsed": sample.elapsed}
        message = {
            "run": run,
            "processes": processes,
            "components": self.composable(),
            "readiness": sample.extra.get("readiness"),
            "lifecycle": sample.extra.get("lifecycle") or [],
        }
        hub.publish(json.dumps(message, separators=(",", ":")).encode())

    # --- asked by the browsers' threads -----------------------------------------------------

    def call(
        self, fn: Callable[[Callable[[dict[str, object]], None]], None], timeout: float
    ) -> dict[str, object]:
        """Run ``fn(reply)`` on the loop thread; its reply, or an error once ``timeout`` passed."""
        done = threading.Event()
        result: list[dict[str, object]] = []

        def reply(payload: dict[str, object]) -> None:
            if not result:
                result.append(payload)
                done.set()

        loop = self.loop
        if loop is None or self.hub.closed:
            return {"ok": False, "error": "the launch has ended", "status": 1}
        loop.call_soon(lambda: fn(reply))
        if not done.wait(timeout):
            return {"ok": False, "error": f"no answer from the run within {timeout:.0f} s"}
        return result[0]

    def request(self, request: dict[str, object], timeout: float) -> dict[str, object]:
        """A control request (``mlaunch ctl``'s protocol) carried out on the loop thread."""
        from mlaunch.parts.control_socket import answer_request

        def carry_out(reply: Callable[[dict[str, object]], None]) -> None:
            def fail(error: str, status: int = 1, **more: object) -> None:
                reply({"ok": False, "error": error, "status": status, **more})

            answer_request(
                self.control,
                request,
                by="page",
                answer=lambda payload: reply({"ok": True, **payload}),
                fail=fail,
            )

        return self.call(carry_out, timeout)

    def follow_start(self, label: str, lines: int) -> dict[str, object]:
        """The label's last ``lines`` (from its log file) and the number of the next line, read
        together on the loop thread, so the follow that continues from there misses nothing."""

        def tail(reply: Callable[[dict[str, object]], None]) -> None:
            from mlaunch.parts.control import ControlError

            try:
                control = self.control()
                resolved = control.resolve(label)
                text = control.logs(resolved, lines)
            except ControlError as e:
                reply({"ok": False, "error": str(e)})
                return
            reply({"ok": True, "label": resolved, "lines": text, "next": self.hub.end(resolved)})

        return self.call(tail, 10.0)

    @property
    def run_id(self) -> str:
        """The run's id (the evidence bundle's name)."""
        return self.supervisor.run_id

    def evidence_bundle(self) -> tuple[bytes | None, str]:
        """The evidence of the run so far as a .tar.gz, or why not. The processes are copied on
        the loop thread (as they are at one moment); the files are written and packed here, in
        the asking browser's thread, so the run never waits for them."""
        if self.evidence is None:
            return None, "this run has no evidence writer"
        if not self.evidence_busy.acquire(blocking=False):
            return None, "an evidence bundle is being made; ask again when it is done"
        try:

            def freeze(reply: Callable[[dict[str, object]], None]) -> None:
                processes = [copy.copy(p) for p in self.supervisor.processes]
                reply({"ok": True, "processes": processes})

            taken = self.call(freeze, 10.0)
            if not taken.get("ok"):
                return None, str(taken.get("error"))
            hub = self.hub
            with hub.lock:
                rings = {label: list(lines) for label, lines in hub.lines.items()}
            processes = taken["processes"]
            assert isinstance(processes, list)
            return self.evidence(processes, rings), ""
        except Exception as e:  # a bundle that cannot be made is said, the run goes on
            return None, f"the evidence bundle could not be made: {type(e).__name__}: {e}"
        finally:
            self.evidence_busy.release()

    def close(self) -> None:
        self.supervisor.records.unsubscribe(self._on_record)
        if self._sampled in self.metrics.listeners:
            self.metrics.listeners.remove(self._sampled)
        self.hub.close()
        for server in self.servers:
            server.shutdown()
            server.server_close()
        if self.loop is not None:
            self.loop.close()
