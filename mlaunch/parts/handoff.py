"""Handing ROS work between worker threads and the supervisor's loop thread.

``LoopCall`` brings results back into the loop (lifecycle driving and the smoke checks post
there from their ROS threads); ``SharedGraph`` is the one private RosGraph a run starts, on
first use, from whichever thread needs it first.
"""

from __future__ import annotations

import os
import queue
import selectors
import threading
from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from mlaunch.parts.bridge import RosGraph


# --- handing work back to the supervisor's loop ---------------------------------------------------


class LoopCall:
    """``call_soon(fn)`` from any thread: fn runs in the supervisor's loop thread, in order.

    A queue plus a pipe registered with the supervisor's selector, so a result arriving from a
    ROS thread wakes the loop at once instead of waiting for its next timer.
    """

    def __init__(self, selector: selectors.BaseSelector) -> None:
        self._selector = selector
        self._queue: queue.SimpleQueue[Callable[[], None]] = queue.SimpleQueue()
        self._read, self._write = os.pipe()
        os.set_blocking(self._read, False)
        os.set_blocking(self._write, False)
        selector.register(self._read, selectors.EVENT_READ, self._run)
        self._closed = False

    def call_soon(self, fn: Callable[[], None]) -> None:
        if self._closed:
            return
        self._queue.put(fn)
        try:
            os.write(self._write, b"x")
        except (BlockingIOError, OSError):
            pass  # a full pipe already wakes the loop; a closed one means the run is over

    def _run(self, fd: int) -> None:
        try:
            while os.read(fd, 4096):
                pass
        except BlockingIOError:
            pass
        self.run_pending()

    def run_pending(self) -> None:
        """Run what is queued now, in the loop's thread (also once the loop has ended)."""
        while True:
            try:
                fn = self._queue.get_nowait()
            except queue.Empty:
                return
            fn()

    def close(self) -> None:
        if self._closed:
            return
        self._closed = True
        try:
            self._selector.unregister(self._read)
        except (KeyError, ValueError, RuntimeError, AttributeError):
            pass  # the supervisor closed its selector already
        for fd in (self._read, self._write):
            try:
                os.close(fd)
            except OSError:
                pass


class SharedGraph:
    """One private RosGraph, started on first use from whichever thread needs it first."""

    def __init__(self, environ: Mapping[str, str], node_name: str) -> None:
        self.environ = dict(environ)
        self.node_name = node_name
        self._lock = threading.Lock()
        self._graph: RosGraph | None = None
        self._closed = False

    def get(self) -> RosGraph:
        from mlaunch.parts.bridge import GraphNotRunning, RosGraph

        with self._lock:
            if self._closed:
                raise GraphNotRunning("the launch is over: the ROS graph bridge is closed")
            if self._graph is None:
                graph = RosGraph(node_name=self.node_name, environ=self.environ)
                graph.start()
                self._graph = graph
            return self._graph

    @property
    def started(self) -> bool:
        return self._graph is not None

    def close(self) -> None:
        with self._lock:
            self._closed = True
            graph, self._graph = self._graph, None
        if graph is not None:
            graph.close()
