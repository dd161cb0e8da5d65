"""The rclpy bridge against real nodes (tests/nodes/*) in a private ROS domain.

Every test that starts nodes uses the `ros_env` fixture (its own ROS_DOMAIN_ID, localhost
discovery) for the children and for the RosGraph, and stops every child in a finally block.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

import pytest
from conftest import REPO, requires_rclpy
from procutil import wait_until

from mlaunch.parts.bridge import RosGraph
from mlaunch.parts.graph_types import (
    INSTALL_HINT,
    GraphNotRunning,
    RosInputError,
    RosTimeout,
    RosUnavailable,
    TransitionEvent,
    domain_id_from,
    message_class,
    node_fqn,
)

NODES = Path(__file__).resolve().parent / "nodes"
STARTUP = 15.0  # generous: two rclpy interpreters starting at once on 2 busy cores


@dataclass
class Child:
    """A test node program running as a child process, its output going to files."""

    name: str
    proc: subprocess.Popen[bytes]
    stdout: Path
    stderr: Path
    returncode: int | None = field(default=None)

    def out(self) -> str:
        return self.stdout.read_text(errors="replace")

    def err(self) -> str:
        return self.stderr.read_text(errors="replace")

    def stop(self) -> int:
        """SIGINT, then SIGKILL after 10 s; the exit status."""
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGINT)
        try:
            self.returncode = self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.returncode = self.proc.wait(timeout=5)
        return self.returncode


class Children:
    """Starts test node programs with the test's ROS env; stop_all() is called in finally."""

    def __init__(self, env: dict[str, str], tmp_path: Path) -> None:
        self.env = env
        self.tmp_path = tmp_path
        self.started: list[Child] = []

    def start(self, label: str, script: str, *args: str) -> Child:
        out, err = self.tmp_path / f"{label}.out", self.tmp_path / f"{label}.err"
        with out.open("wb") as stdout, err.open("wb") as stderr:
            proc = subprocess.Popen(
                [sys.executable, str(NODES / script), *args],
                env=self.env,
                stdout=stdout,
                stderr=stderr,
                stdin=subprocess.DEVNULL,
            )
        child = Child(label, proc, out, err)
        self.started.append(child)
        return child

    def stop_all(self) -> None:
        for child in self.started:
            child.stop()


@contextmanager
def ros_world(env: dict[str, str], tmp_path: Path) -> Iterator[tuple[Children, RosGraph]]:
    """Children to start and a started RosGraph on the same private domain; all closed after."""
    children = Children(env, tmp_path)
    graph = RosGraph(environ=env)
    try:
        graph.start()
        yield children, graph
    finally:
        graph.close()
        children.stop_all()


def assert_clean_exit(child: Child) -> None:
    """The child ended on SIGINT with status 0 and printed no traceback."""
    assert child.stop() == 0, f"{child.name} exited {child.returncode}: {child.err()[-2000:]}"
    assert "Traceback" not in child.err(), child.err()


def run_python(code: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, cwd=REPO, timeout=60
    )


# -- no ROS needed ----------------------------------------------------------------------------


def test_importing_the_bridge_does_not_import_rclpy() -> None:
    result = run_python(
        "import sys, time\n"
        "t = time.perf_counter()\n"
        "import mlaunch.parts.bridge\n"
        "ms = (time.perf_counter() - t) * 1000\n"
        "ros = sorted(m for m in sys.modules if m.split('.')[0] in "
        "('rclpy', 'rpyutils', 'std_msgs', 'lifecycle_msgs', 'rosidl_runtime_py'))\n"
        "print(ros, round(ms, 1))\n"
    )
    assert result.returncode == 0, result.stderr
    loaded, import_ms = result.stdout.rsplit(" ", 1)
    assert loaded == "[]"
    print(f"import mlaunch.parts.bridge: {import_ms.strip()} ms")


def test_without_rclpy_start_says_how_to_install_it() -> None:
    result = run_python(
        "import sys\n"
        "sys.modules['rclpy'] = None  # as if the ros extra were not installed\n"
        "from mlaunch.parts.bridge import RosGraph, RosUnavailable\n"
        "graph = RosGraph()\n"
        "try:\n"
        "    graph.start()\n"
        "except RosUnavailable as exc:\n"
        "    print('unavailable:', exc)\n"
    )
    assert result.returncode == 0, result.stderr
    assert result.stdout.startswith("unavailable: ")
    assert INSTALL_HINT in result.stdout


def test_bad_domain_id_node_name_and_transition_are_named() -> None:
    with pytest.raises(RosInputError, match=r"ROS_DOMAIN_ID='abc'.*0 to 232"):
        RosGraph(environ={"ROS_DOMAIN_ID": "abc"})
    with pytest.raises(RosInputError, match="'500'"):
        domain_id_from({"ROS_DOMAIN_ID": "500"})
    assert domain_id_from({}) == 0
    assert domain_id_from({"ROS_DOMAIN_ID": " 42 "}) == 42
    with pytest.raises(RosInputError, match="'bad name'"):
        RosGraph(node_name="bad name")
    with pytest.raises(RosInputError, match="'/robot1/2d'"):
        node_fqn("/robot1/2d")
    assert node_fqn("robot1/camera") == "/robot1/camera"
    with pytest.raises(RosInputError, match="'LaserScan'.*package/msg/Type"):
        message_class("LaserScan")
    with pytest.raises(RosUnavailable, match="'no_such_msgs/msg/Thing'.*no_such_msgs.msg"):
        message_class("no_such_msgs/msg/Thing")
    graph = RosGraph(environ={})
    with pytest.raises(GraphNotRunning, match="start"):
        graph.node_names()


# -- against live nodes -----------------------------------------------------------------------


@requires_rclpy
@pytest.mark.serial  # a measured rate of 20 Hz (14 Hz with three other workers at load 24)
def test_nodes_topics_services_and_rate(ros_env: dict[str, str], tmp_path: Path) -> None:
    with ros_world(ros_env, tmp_path) as (children, graph):
        talker = children.start(
            "talker", "talker.py", "--ros-args", "-r", "__ns:=/robot1", "-p", "rate:=20"
        )
        intro = children.start("introspect", "introspect.py", "--ros-args", "-r", "__ns:=/robot1")
        expected = {"/robot1/talker", "/robot1/introspect"}
        services = {"/robot1/talker/get_parameters", "/robot1/introspect/list_parameters"}
        # A node shows up before its endpoints do: wait for all three.
        assert graph.wait_for(
            lambda g: (
                expected <= g.node_names()
                and "/robot1/chatter" in g.topic_types()
                and services <= g.service_names()
            ),
            STARTUP,
        ), (graph.node_names(), graph.topic_types(), graph.service_names())
        assert graph.fqn not in graph.node_names()
        assert graph.topic_types()["/robot1/chatter"] == ["std_msgs/msg/String"]
        assert not any(name.startswith(graph.fqn) for name in graph.service_names())

        chatter = graph.watch_topic("robot1/chatter")  # type learnt from the graph
        assert chatter.wait_count(30, 10), chatter
        assert chatter.type_name == "std_msgs/msg/String"
        assert chatter.last_message().data.startswith("Hello World: ")
        assert chatter.first_at is not None and chatter.last_at is not None
        assert 16.0 <= chatter.rate(1.0) <= 24.0, chatter.rate(1.0)
        assert graph.watch_topic("/robot1/chatter") is chatter

        assert wait_until(lambda: intro.out().endswith("\n"), STARTUP)
        assert json.loads(intro.out())["fqn"] == "/robot1/introspect"

        assert_clean_exit(talker)
        assert graph.wait_for(lambda g: "/robot1/talker" not in g.node_names(), 10)
        assert_clean_exit(intro)


@requires_rclpy
def test_topic_qos_latched_best_effort_and_silent(ros_env: dict[str, str], tmp_path: Path) -> None:
    with ros_world(ros_env, tmp_path) as (children, graph):
        latched = children.start("latched", "talker.py", "--latched", "--count", "1")
        best_effort = children.start(
            "best_effort", "talker.py", "--best-effort", "--ros-args", "-r", "chatter:=fast"
        )
        silent = children.start("silent", "silent.py")
        # The latched talker publishes its only message before anyone subscribes.
        assert wait_until(lambda: "Hello World: 1" in latched.err(), STARTUP), latched.err()

        late = graph.watch_topic("/chatter", "std_msgs/msg/String")
        assert late.wait_count(1, 10), "a late subscriber must get the latched message"
        assert late.last_message().data == "Hello World: 1"
        fast = graph.watch_topic("/fast")
        assert fast.wait_count(3, STARTUP), "best-effort publishers must be received too"

        with pytest.raises(RosInputError, match="std_msgs/msg/Nope.*no message Nope"):
            graph.watch_topic("/other", "std_msgs/msg/Nope")
        with pytest.raises(RosInputError, match="already watched as std_msgs/msg/String"):
            graph.watch_topic("/chatter", "sensor_msgs/msg/LaserScan")
        with pytest.raises(RosInputError, match="'bad topic'"):
            graph.watch_topic("bad topic")

        quiet = graph.watch_topic("/silent")
        assert wait_until(lambda: quiet.subscribed, STARTUP)
        assert not quiet.wait_count(1, 0.5)
        assert quiet.count == 0 and quiet.rate() == 0.0 and quiet.last_message() is None
        for child in (latched, best_effort, silent):
            assert_clean_exit(child)


@requires_rclpy
def test_lifecycle_configure_activate(ros_env: dict[str, str], tmp_path: Path) -> None:
    with ros_world(ros_env, tmp_path) as (children, graph):
        node = children.start(
            "camera", "lifecycle_node.py", "--ros-args", "-r", "__node:=camera", "-r", "__ns:=/r1"
        )
        events: list[TransitionEvent] = []
        graph.on_transition("/r1/camera", events.append)

        def broken(event: TransitionEvent) -> None:
            raise ValueError(f"broken callback saw {event.goal_state}")

        graph.on_transition("/r1/camera", broken)  # must not stop the others
        assert graph.lifecycle_state("/r1/camera", STARTUP) == "unconfigured"

        configured = graph.change_state("/r1/camera", "configure", 5)
        assert configured.ok and configured.state == "inactive", configured
        activated = graph.change_state("r1/camera", "activate", 5)
        assert activated.ok, activated
        states = _concurrently(4, lambda: graph.lifecycle_state("/r1/camera", 5))
        assert states == ["active"] * 4

        status = graph.watch_topic("/r1/status")
        assert status.wait_count(3, 10), "an active node publishes status at 5 Hz"
        assert graph.wait_for(lambda g: len(events) >= 4, 5), events
        steps = [(e.transition, e.start_state, e.goal_state) for e in events[:4]]
        assert steps == [
            ("configure", "unconfigured", "configuring"),
            ("configure", "configuring", "inactive"),
            ("activate", "inactive", "activating"),
            ("activate", "activating", "active"),
        ]
        assert all(e.node == "/r1/camera" for e in events)
        where, error = graph.callback_errors[0]
        assert where == "/r1/camera/transition_event" and isinstance(error, ValueError)

        again = graph.change_state("/r1/camera", "activate", 5)
        assert not again.ok and again.state == "active", again
        shutdown = graph.change_state("/r1/camera", "shutdown", 5)
        assert shutdown.ok and shutdown.state == "finalized", shutdown
        with pytest.raises(RosInputError, match="'launch'.*configure"):
            graph.change_state("/r1/camera", "launch", 1)
        assert node.out().splitlines()[:3] == [
            "transition configure: success",
            "transition activate: success",
            "transition shutdown: success",
        ]
        assert_clean_exit(node)


@requires_rclpy
def test_lifecycle_failures_are_reported(ros_env: dict[str, str], tmp_path: Path) -> None:
    with ros_world(ros_env, tmp_path) as (children, graph):
        refuses = children.start(
            "refuses", "lifecycle_node.py", "--fail-configure", "--ros-args", "-r", "__node:=r"
        )
        crashes = children.start(
            "crashes", "lifecycle_node.py", "--crash-on-activate", "--ros-args", "-r", "__node:=c"
        )
        assert graph.lifecycle_state("/r", STARTUP) == "unconfigured"
        refused = graph.change_state("/r", "configure", 5)
        assert not refused.ok and refused.node == "/r" and refused.transition == "configure"
        assert "success=false" in refused.detail and "'unconfigured'" in refused.detail

        assert graph.change_state("/c", "configure", STARTUP).ok
        crashed = graph.change_state("/c", "activate", 1.5)
        assert not crashed.ok and "no answer from /c/change_state" in crashed.detail, crashed
        assert crashes.proc.wait(timeout=5) == 3
        assert crashes.out().splitlines()[-1] == "transition activate: crash"
        assert_clean_exit(refuses)


@requires_rclpy
def test_sigint_just_before_spin_exits_0(ros_env: dict[str, str], tmp_path: Path) -> None:
    """The JSON line is printed right before spinning starts: the window that once lost a signal."""
    children = Children(ros_env, tmp_path)
    try:
        started = [children.start(f"i{n}", "introspect.py") for n in range(3)]
        pending = list(started)

        def all_printed() -> bool:
            for child in [c for c in pending if c.out().endswith("\n")]:
                child.proc.send_signal(signal.SIGINT)
                pending.remove(child)
            return not pending

        assert wait_until(all_printed, STARTUP, interval=0.005), "introspect printed no JSON line"
        for child in started:
            assert child.proc.wait(timeout=5) == 0, child.err()
            assert "Traceback" not in child.err(), child.err()
    finally:
        children.stop_all()


@requires_rclpy
def test_a_second_signal_ends_a_node_stuck_in_its_teardown(
    ros_env: dict[str, str], tmp_path: Path
) -> None:
    """Python runs no handler while the main thread is in native code (a middleware teardown
    that hangs): the first signal is recorded, and the second must end the program by its
    default action, or the supervisor's ladder needs SIGKILL."""
    children = Children(ros_env, tmp_path)
    try:
        child = children.start("stuck", "talker.py", "--slow-teardown", "60")
        assert wait_until(lambda: "Publishing" in child.err(), STARTUP), child.err()
        child.proc.send_signal(signal.SIGINT)
        assert wait_until(lambda: "tearing down" in child.err(), 10), child.err()
        child.proc.send_signal(signal.SIGTERM)
        assert child.proc.wait(timeout=10) == -signal.SIGTERM
    finally:
        children.stop_all()


@requires_rclpy
def test_absent_node_times_out_at_the_deadline(ros_env: dict[str, str]) -> None:
    with RosGraph(environ=ros_env) as graph:
        started = time.monotonic()
        assert not graph.wait_for(lambda g: "/nobody" in g.node_names(), 0.5)
        # Not before its deadline, and not much after (generous: the machine may be loaded).
        assert 0.5 <= time.monotonic() - started < 5.0
        with pytest.raises(RosTimeout, match=r"/nobody/get_state not available within 0.3 s"):
            graph.lifecycle_state("/nobody", 0.3)
        result = graph.change_state("/nobody", "configure", 0.3)
        assert not result.ok and "not available" in result.detail


@requires_rclpy
def test_close_releases_waiters_threads_and_context(ros_env: dict[str, str]) -> None:
    with RosGraph(environ=ros_env):
        pass  # Fast DDS keeps a few process-wide threads from its first use on: start them now
    native_before = set(os.listdir("/proc/self/task"))
    threads_before = set(threading.enumerate())
    graph = RosGraph(environ=ros_env)
    graph.start()
    # The native threads this graph started (DDS participant, executor): they must all end.
    native_started = set(os.listdir("/proc/self/task")) - native_before
    watch = graph.watch_topic("/never", "std_msgs/msg/String")
    results: list[bool] = []
    waiters = [
        threading.Thread(target=lambda: results.append(watch.wait_count(1, 30))),
        threading.Thread(
            target=lambda: results.append(graph.wait_for(lambda g: "/x" in g.node_names(), 30))
        ),
    ]
    for waiter in waiters:
        waiter.start()
    assert set(threading.enumerate()) - threads_before - set(waiters), "the spin thread runs"
    closing = time.monotonic()
    graph.close()
    for waiter in waiters:
        waiter.join(timeout=5)
    # Released by close(), not by their 30 s deadlines (generous bound for a loaded machine).
    assert results == [False, False] and time.monotonic() - closing < 10.0
    assert set(threading.enumerate()) == threads_before
    # The context is destroyed with close(), and the DDS participant's threads with it. They
    # take a moment to exit, and other threads of the test process may come and go meanwhile,
    # so the check is on exactly the threads this graph started, with a deadline.
    assert native_started
    assert wait_until(lambda: not native_started & set(os.listdir("/proc/self/task")), 3.0)
    assert not graph.running
    with pytest.raises(GraphNotRunning, match="closed"):
        graph.node_names()
    graph.close()  # idempotent


def _concurrently(n: int, fn: Callable[[], str]) -> list[str]:
    """Run fn in n threads at once; their results (an exception fails the test)."""
    results: list[str] = []
    errors: list[BaseException] = []

    def run() -> None:
        try:
            results.append(fn())
        except BaseException as exc:
            errors.append(exc)

    threads = [threading.Thread(target=run) for _ in range(n)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(timeout=10)
    assert not errors, errors
    return results
