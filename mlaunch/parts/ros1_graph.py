"""The ROS 1 graph as a native ROS 1 run's master knows it, read over its XML-RPC API.

``mlaunch test`` on a native ROS 1 run (``mlaunch.parts.ros1_native``) checks it instead of the
ROS 2 graph: a node is up once it is registered with the master (what ``rosnode list`` reads,
``getSystemState``), a service once the master lists it. Python's ``xmlrpc.client`` is all it
needs: no rospy in mlaunch's own environment. A topic's messages are counted by a small helper
under Debian's Python (``ros1_topic_probe.py``, rospy), one per topic, which writes a line per
message; it ends when mlaunch closes its stdin (or is gone).
"""

from __future__ import annotations

import os
import subprocess
import threading
import xmlrpc.client
from typing import Any

from mlaunch.parts.graph_types import GraphNotRunning, RosBridgeError, TopicWatch
from mlaunch.parts.ros1_environ import SYSTEM_PYTHON

# Each call to the master is given this long (a master that does not answer is not up yet).
CALL_TIMEOUT = 2.0
CALLER_ID = "/mlaunch_test"


PROBE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "ros1_topic_probe.py")


class MasterGraph:
    """The graph of one ROS 1 master: its registered nodes, topics and services, and the
    messages of the topics watched."""

    def __init__(self, uri: str) -> None:
        self.uri = uri
        self._probes: list[subprocess.Popen[bytes]] = []
        self._lock = threading.Lock()
        self._closed = False

    def watch_topic(self, topic: str) -> TopicWatch:
        """Counts the topic's messages (any type), through a rospy helper under Debian's Python."""
        from mlaunch.parts.ros1_environ import system_python_env

        watch = TopicWatch(topic, None)
        env = system_python_env(os.environ)
        env["ROS_MASTER_URI"] = self.uri
        try:
            probe = subprocess.Popen(
                [SYSTEM_PYTHON, PROBE, topic],
                stdin=subprocess.PIPE,
                stdout=subprocess.PIPE,
                stderr=subprocess.DEVNULL,
                env=env,
                start_new_session=True,
            )
        except OSError as e:
            watch.error = f"cannot start {SYSTEM_PYTHON} to read ROS 1 messages: {e.strerror}"
            return watch
        with self._lock:
            if self._closed:
                _end(probe)
                watch.error = "the launch is over"
                return watch
            self._probes.append(probe)
        watch.subscribed = True
        threading.Thread(target=_read, args=(probe, watch), daemon=True).start()
        return watch

    def close(self) -> None:
        with self._lock:
            self._closed = True
            probes, self._probes = self._probes, []
        for probe in probes:
            _end(probe)

    def _call(self, method: str, *args: Any) -> Any:
        """One master API call; its value, or RosBridgeError saying why there is none."""
        proxy = xmlrpc.client.ServerProxy(self.uri, transport=_TimeoutTransport())
        try:
            reply = getattr(proxy, method)(CALLER_ID, *args)
        except (OSError, xmlrpc.client.Error) as e:
            raise RosBridgeError(f"the ROS master at {self.uri} does not answer: {e}") from e
        except Exception as e:  # a garbled reply: whatever the parser raised
            raise RosBridgeError(f"the ROS master at {self.uri} sent a bad reply: {e}") from e
        try:
            code, message, value = reply
        except (TypeError, ValueError):
            raise RosBridgeError(f"the ROS master at {self.uri} sent a bad reply: {reply!r}")
        if code != 1:
            raise RosBridgeError(f"the ROS master at {self.uri} refused {method}: {message}")
        return value

    def _system_state(self) -> tuple[list[Any], list[Any], list[Any]]:
        state = self._call("getSystemState")
        try:
            publishers, subscribers, services = state
            return list(publishers), list(subscribers), list(services)
        except (TypeError, ValueError):
            raise RosBridgeError(f"the ROS master at {self.uri} sent a bad system state")

    def node_names(self) -> set[str]:
        """Every node the master has registered (a publisher, subscriber or service of it)."""
        names: set[str] = set()
        for group in self._system_state():
            names.update(_nodes(group))
        return names

    def topic_types(self) -> dict[str, list[str]]:
        out: dict[str, list[str]] = {}
        for entry in self._call("getTopicTypes"):
            if isinstance(entry, list) and len(entry) == 2:
                out.setdefault(str(entry[0]), []).append(str(entry[1]))
        return out

    def service_names(self) -> set[str]:
        return {str(e[0]) for e in self._system_state()[2] if isinstance(e, list) and e}


def _read(probe: subprocess.Popen[bytes], watch: TopicWatch) -> None:
    """The probe's lines: a message each (``m``), or why none can come (``e WHY``)."""
    assert probe.stdout is not None
    for line in probe.stdout:
        if line.startswith(b"m"):
            watch._on_message(None)
        elif line.startswith(b"e "):
            watch.error = line[2:].decode("utf-8", "replace").strip()[:300]
    if watch.error is None and probe.wait() not in (0, -15):
        watch.error = f"the ROS 1 message reader ended with status {probe.returncode}"
    watch._close()


def _end(probe: subprocess.Popen[bytes]) -> None:
    """Close its stdin (it ends on that), then make sure it has."""
    try:
        if probe.stdin is not None:
            probe.stdin.close()
        probe.wait(timeout=2.0)
    except (OSError, subprocess.TimeoutExpired):
        probe.kill()
        probe.wait()


def _nodes(group: list[Any]) -> set[str]:
    """The node names of one getSystemState list ([name, [node, ...]] entries)."""
    found: set[str] = set()
    for entry in group:
        if isinstance(entry, list) and len(entry) == 2 and isinstance(entry[1], list):
            found.update(str(n) for n in entry[1])
    return found


class _TimeoutTransport(xmlrpc.client.Transport):
    def make_connection(self, host: Any) -> Any:
        connection = super().make_connection(host)
        connection.timeout = CALL_TIMEOUT
        return connection


class SharedMaster:
    """What the smoke checks hold instead of the ROS 2 graph on a native ROS 1 run (the
    interface of ``mlaunch.parts.handoff.SharedGraph``)."""

    def __init__(self, uri: str) -> None:
        self._graph = MasterGraph(uri)
        self._closed = threading.Event()

    def get(self) -> MasterGraph:
        if self._closed.is_set():
            raise GraphNotRunning("the launch is over: the ROS master is no longer watched")
        return self._graph

    @property
    def started(self) -> bool:
        return True

    def close(self) -> None:
        self._closed.set()
        self._graph.close()
