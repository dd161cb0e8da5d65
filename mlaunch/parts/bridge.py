"""The one module of mlaunch that talks to ROS: a private rclpy node watching the ROS graph.

`mlaunch test` asks it whether "the ROS graph is up" (nodes, topics, services, message rates)
and lifecycle bring-up drives managed nodes through it. A plain launch never touches it, so
rclpy and every message package are imported inside functions, never at module level: importing
this module costs a few stdlib modules only.

Threading: `RosGraph.start()` makes its own rclpy Context (never the global one, so no signal
handlers are installed and the launcher's SIGINT handling stays its own) and one node, spun by a
SingleThreadedExecutor in one daemon thread. Entities (subscriptions, clients, the poll timer)
are created inside that thread via executor tasks; graph queries are thread-safe rcl calls made
from the caller's thread; service calls are sent from the caller's thread and awaited on a
threading.Event with a deadline. Every wait is bounded, and `close()` wakes every waiter.

The domain id comes from the `environ` mapping handed in (the environment the launched nodes
get), passed to rcl as an init option. The RMW implementation and the discovery range
(ROS_AUTOMATIC_DISCOVERY_RANGE) are read by the middleware from this process's os.environ.
"""

from __future__ import annotations

import functools
import itertools
import os
import threading
import time
from collections.abc import Callable, Mapping
from typing import Any

from mlaunch.parts.discovery import Settling
from mlaunch.parts.graph_types import (
    INSTALL_HINT,
    NODE_NAME,
    TRANSITION_IDS,
    GraphNotRunning,
    PendingCall,
    RosBridgeError,
    RosInputError,
    RosTimeout,
    RosUnavailable,
    TopicWatch,
    TransitionEvent,
    TransitionResult,
    domain_id_from,
    implied_transition,
    import_ros,
    join_name,
    message_class,
    node_fqn,
    qos_for,
    same_type,
    topic_name,
    transition_label,
)

# rclpy exposes no graph guard condition to Python (ros2/rclpy#929), so graph waits poll.
POLL_PERIOD = 0.05
# Creating an entity in the executor thread takes milliseconds; this only bounds a wedged spin.
ENTITY_TIMEOUT = 5.0
# The read-back of the state after a transition never waits longer than this.
STATE_READBACK_TIMEOUT = 1.0
MAX_RECORDED_ERRORS = 100
_instances = itertools.count()


class RosGraph:
    """A private rclpy Context + node spun by an executor in a daemon thread."""

    def __init__(
        self, *, node_name: str | None = None, environ: Mapping[str, str] | None = None
    ) -> None:
        # Default name: hidden (leading '_', like launch_testing_ros' '_test_node_<n>') and
        # unique per process, so it never clashes with, or hides, a launched node's name.
        count = next(_instances)
        self.node_name = node_name or f"_mlaunch_{os.getpid()}" + (f"_{count}" if count else "")
        if not NODE_NAME.match(self.node_name):
            raise RosInputError(
                f"RosGraph node_name {self.node_name!r} is not a valid ROS node name "
                "(letters, digits and '_', not starting with a digit)"
            )
        self.domain_id = domain_id_from(os.environ if environ is None else environ)
        self.callback_errors: list[tuple[str, BaseException]] = []
        self._state = "new"  # new -> running -> closed
        self._lock = threading.Lock()
        self._wake = threading.Condition()
        self._stopping = threading.Event()
        self._context: Any = None
        self._node: Any = None
        self._executor: Any = None
        self._thread: threading.Thread | None = None
        self._watches: dict[str, TopicWatch] = {}
        self._pending: list[TopicWatch] = []
        # Raw subscriptions waiting for a publisher: (topic, keep(topic, type, cdr bytes)).
        self._raw_pending: list[tuple[str, Callable[[str, str, bytes], None]]] = []
        self._poll_timer: Any = None
        self._clients: dict[str, Any] = {}
        self._settling = Settling()  # per service: when its client first saw it
        self._calls: list[PendingCall] = []
        self._transition_callbacks: dict[str, list[Callable[[TransitionEvent], None]]] = {}

    # -- life cycle of the bridge itself ----------------------------------------------------

    def start(self) -> None:
        """Create the context, node and executor thread; RosUnavailable without rclpy."""
        with self._lock:
            if self._state != "new":
                raise GraphNotRunning(f"RosGraph {self.node_name!r} was already started")
            self._state = "starting"
        try:
            self._create()
        except BaseException:
            self._destroy()
            with self._lock:
                self._state = "closed"
            raise
        with self._lock:
            self._state = "running"

    def _create(self) -> None:
        import_ros("rclpy")
        from rclpy.context import Context
        from rclpy.executors import SingleThreadedExecutor
        from rclpy.node import Node
        from rclpy.parameter import Parameter

        self._context = Context()
        # args=[]: never parse this process's sys.argv (pytest's, mlaunch's) as ROS arguments.
        # initialize_logging=False: the launcher owns logging; no ~/.ros/log files from here.
        self._context.init([], initialize_logging=False, domain_id=self.domain_id)
        self._node = Node(
            self.node_name,
            context=self._context,
            use_global_arguments=False,
            enable_rosout=False,
            start_parameter_services=False,
            # Without this every node serves <fqn>/get_type_description; ours would show up.
            parameter_overrides=[Parameter("start_type_description_service", value=False)],
        )
        self._executor = SingleThreadedExecutor(context=self._context)
        self._executor.add_node(self._node)
        self._thread = threading.Thread(
            target=self._spin, name=f"mlaunch-ros-{self.node_name}", daemon=True
        )
        self._thread.start()

    def _spin(self) -> None:
        from rclpy.executors import ExternalShutdownException

        while not self._stopping.is_set():
            try:
                # Returns early whenever a task is queued or wake() is called.
                self._executor.spin_once(timeout_sec=0.5)
            except ExternalShutdownException:
                break
            except Exception as exc:  # a dying spin thread would freeze every watch silently
                self._record_error("executor", exc)
                self._stopping.wait(0.01)  # back off: never spin hot on a repeating error

    def close(self) -> None:
        """Stop the thread, destroy the node and shut the context down. Idempotent."""
        with self._lock:
            if self._state in ("new", "closed"):
                self._state = "closed"
                return
            self._state = "closed"
        self._stopping.set()
        self._release_waiters()
        if self._executor is not None:
            # A task, not wake(): wake() only makes spin_once rebuild its wait set and wait on
            # (up to its 0.5 s timeout); a ready task makes it return at once.
            self._executor.create_task(lambda: None)
        if self._thread is not None:
            self._thread.join(timeout=ENTITY_TIMEOUT)
        self._destroy()

    def _record_error(self, where: str, exc: BaseException) -> None:
        # Bounded: a callback failing on every message must not grow memory without end.
        if len(self.callback_errors) < MAX_RECORDED_ERRORS:
            self.callback_errors.append((where, exc))

    def _release_waiters(self) -> None:
        for call in list(self._calls):
            call.done.set()
        for watch in self._watches.values():
            watch._close()
        with self._wake:
            self._wake.notify_all()

    def _destroy(self) -> None:
        if self._executor is not None:
            self._executor.shutdown(timeout_sec=0)
        if self._node is not None:
            self._node.destroy_node()
        if self._context is not None:
            self._context.try_shutdown()
            # Frees the rcl context and with it the DDS participant and its threads.
            self._context.destroy()
        self._executor = self._node = self._context = None

    def __enter__(self) -> RosGraph:
        self.start()
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()

    @property
    def running(self) -> bool:
        """True between start() and close()."""
        return self._state == "running"

    @property
    def fqn(self) -> str:
        """This bridge's own node name, as it appears in the graph."""
        return f"/{self.node_name}"

    def _require_running(self) -> Any:
        if self._state != "running":
            raise GraphNotRunning(
                f"RosGraph {self.node_name!r} is {self._state}: "
                "call start() first, or use 'with RosGraph() as graph:'"
            )
        return self._node

    def _in_executor(self, fn: Callable[[], Any]) -> Any:
        """Run fn in the executor thread (where entities are made) and return its result."""
        self._require_running()
        if threading.current_thread() is self._thread:
            return fn()
        done = threading.Event()
        box: dict[str, Any] = {}

        def task() -> None:
            try:
                box["value"] = fn()
            except BaseException as exc:  # handed to the caller below
                box["error"] = exc
            finally:
                done.set()

        self._executor.create_task(task)
        if not done.wait(ENTITY_TIMEOUT):
            raise RosTimeout(f"the ROS executor thread did not run a task in {ENTITY_TIMEOUT} s")
        if "error" in box:
            raise box["error"]
        return box.get("value")

    # -- graph queries -------------------------------------------------------------------------

    def _query(self, ask: Callable[[Any], Any]) -> Any:
        """ask(node) from the caller's thread (rcl graph calls are thread-safe)."""
        node = self._require_running()
        try:
            return ask(node)
        except Exception:
            # close() from another thread destroyed the node under us: say that, not InvalidHandle.
            self._require_running()
            raise

    def node_names(self) -> set[str]:
        """Fully qualified names ('/ns/name') of every node in the domain except this one."""
        pairs = self._query(lambda node: node.get_node_names_and_namespaces())
        return {join_name(ns, name) for name, ns in pairs} - {self.fqn}

    def topic_types(self) -> dict[str, list[str]]:
        """Every topic in the graph with its type names ('pkg/msg/Type')."""
        pairs = self._query(lambda node: node.get_topic_names_and_types())
        return {name: list(types) for name, types in pairs}

    def service_names(self) -> set[str]:
        """Every service in the graph (this bridge serves none)."""
        pairs = self._query(lambda node: node.get_service_names_and_types())
        own = self.fqn + "/"
        return {name for name, _types in pairs if not name.startswith(own)}

    def wait_for(self, predicate: Callable[[RosGraph], bool], timeout: float) -> bool:
        """Wait until predicate(self) is true; False at the deadline or when closed.

        Re-checked on every message or transition event and at least every POLL_PERIOD (the
        graph itself gives Python no change notification). An exception from the predicate
        propagates, unless the graph was closed meanwhile.
        """
        self._require_running()
        deadline = time.monotonic() + timeout
        while True:
            try:
                if predicate(self):
                    return True
            except Exception:
                if self._state != "running":
                    return False  # closed under the predicate's feet
                raise
            remaining = deadline - time.monotonic()
            if remaining <= 0 or self._state != "running":
                return False
            with self._wake:
                self._wake.wait(min(POLL_PERIOD, remaining))

    def _notify(self) -> None:
        with self._wake:
            self._wake.notify_all()

    # -- topics --------------------------------------------------------------------------------

    def watch_topic(self, topic: str, type_name: str | None = None) -> TopicWatch:
        """Count the messages on `topic` ('/scan' or 'scan', taken as absolute).

        Without `type_name` the type is learnt from the graph once a publisher appears. One
        watch per topic: watching it again returns the same TopicWatch.
        """
        self._require_running()
        name = topic_name(topic)
        if type_name is not None:
            message_class(type_name)  # a bad type is the caller's error, raised here
        with self._lock:
            watch = self._watches.get(name)
            if watch is not None:
                return same_type(watch, type_name)
            watch = TopicWatch(name, type_name)
            watch._listeners.append(self._notify)
            self._watches[name] = watch
        self._in_executor(lambda: self._add_pending(watch))
        return watch

    def clock(self) -> TopicWatch:
        """Watch /clock (rosgraph_msgs/msg/Clock), published by simulators."""
        return self.watch_topic("/clock", "rosgraph_msgs/msg/Clock")

    def record(self, topic: str, keep: Callable[[str, str, bytes], None]) -> None:
        """Hand each message of ``topic`` to ``keep(topic, type, cdr_bytes)`` undecoded (the
        test's recording), from when the topic has a publisher; ``keep`` must be quick."""
        self._require_running()
        name = topic_name(topic)
        self._in_executor(lambda: self._add_raw(name, keep))

    def _add_raw(self, name: str, keep: Callable[[str, str, bytes], None]) -> None:
        # Runs in the executor thread.
        if not self._try_raw(name, keep):
            self._raw_pending.append((name, keep))
            self._poll()

    def _try_raw(self, name: str, keep: Callable[[str, str, bytes], None]) -> bool:
        publishers = self._node.get_publishers_info_by_topic(name)
        if not publishers:
            return False
        type_name = sorted({info.topic_type for info in publishers})[0]
        try:
            cls = message_class(type_name)
        except RosBridgeError:
            return True  # a type this Python cannot load: not recorded
        callback = self._guarded(functools.partial(keep, name, type_name), name)
        self._node.create_subscription(cls, name, callback, qos_for(publishers), raw=True)
        return True

    def _add_pending(self, watch: TopicWatch) -> None:
        # Runs in the executor thread.
        if self._try_subscribe(watch):
            return
        self._pending.append(watch)
        self._poll()

    def _poll(self) -> None:
        if self._poll_timer is None:
            self._poll_timer = self._node.create_timer(POLL_PERIOD, self._poll_pending)
        elif self._poll_timer.is_canceled():
            self._poll_timer.reset()

    def _poll_pending(self) -> None:
        # Runs in the executor thread, at POLL_PERIOD while a watch waits for its publisher.
        self._pending = [w for w in self._pending if not self._try_subscribe(w)]
        self._raw_pending = [(n, k) for n, k in self._raw_pending if not self._try_raw(n, k)]
        if not self._pending and not self._raw_pending:
            self._poll_timer.cancel()

    def _try_subscribe(self, watch: TopicWatch) -> bool:
        """Subscribe once the topic has publishers; True when the watch needs no more polling."""
        publishers = self._node.get_publishers_info_by_topic(watch.topic)
        if not publishers:
            return False
        offered = sorted({info.topic_type for info in publishers})
        watch.type_name = watch.type_name or offered[0]
        if watch.type_name not in offered:
            watch.error = (
                f"{watch.topic} is published as {', '.join(offered)}, not {watch.type_name}"
            )
        try:
            cls = message_class(watch.type_name)
        except RosBridgeError as exc:
            watch.error = str(exc)
            return True
        self._node.create_subscription(
            cls, watch.topic, self._guarded(watch._on_message, watch.topic), qos_for(publishers)
        )
        watch.subscribed = True
        return True

    def _guarded(self, callback: Callable[[Any], None], where: str) -> Callable[[Any], None]:
        """Wrap a callback so an exception is recorded instead of killing the spin thread."""

        def guarded(arg: Any) -> None:
            try:
                callback(arg)
            except Exception as exc:
                self._record_error(where, exc)

        return guarded

    # -- lifecycle (managed) nodes -------------------------------------------------------------

    def lifecycle_state(self, node: str, timeout: float) -> str:
        """The current state label of managed node `node` ('unconfigured', 'active', ...).

        Raises RosTimeout when `<node>/get_state` does not appear or answer in time.
        """
        from lifecycle_msgs.srv import GetState

        fqn = node_fqn(node)
        deadline = time.monotonic() + timeout
        response = self._call(f"{fqn}/get_state", GetState, GetState.Request(), deadline, timeout)
        return str(response.current_state.label)

    # -- parameters ----------------------------------------------------------------------------

    def parameter(self, node: str, name: str, timeout: float) -> tuple[bool, Any]:
        """(whether ``node`` has parameter ``name``, its value as Python) from the node's
        ``get_parameters`` service; RosTimeout when it does not appear or answer in time."""
        from rcl_interfaces.srv import GetParameters

        fqn = node_fqn(node)
        deadline = time.monotonic() + timeout
        request = GetParameters.Request(names=[name])
        service = f"{fqn}/get_parameters"
        response = self._call(service, GetParameters, request, deadline, timeout)
        if not response.values:
            return False, None
        return parameter_value(response.values[0])

    def change_state(self, node: str, transition: str, timeout: float) -> TransitionResult:
        """Ask managed node `node` for `transition` ('configure', 'activate', ...).

        Never raises for a node that refuses, dies or never answers: that is an ok=False result
        whose `detail` says which; bad arguments raise RosInputError.
        """
        from lifecycle_msgs.srv import ChangeState

        fqn, label = node_fqn(node), transition_label(transition)
        request = ChangeState.Request()
        # The label takes precedence in rclcpp and rclpy; it also picks the right 'shutdown'.
        request.transition.id, request.transition.label = TRANSITION_IDS[label], label
        deadline = time.monotonic() + timeout
        try:
            response = self._call(f"{fqn}/change_state", ChangeState, request, deadline, timeout)
        except RosTimeout as exc:
            return TransitionResult(False, fqn, label, str(exc))
        state = self._read_back_state(fqn, deadline)
        now = f"; it is now {state!r}" if state else ""
        if response.success:
            return TransitionResult(True, fqn, label, f"{label} of {fqn} succeeded{now}", state)
        detail = f"{label} of {fqn} failed: the node answered success=false{now}"
        return TransitionResult(False, fqn, label, detail, state)

    def _read_back_state(self, fqn: str, deadline: float) -> str | None:
        budget = min(STATE_READBACK_TIMEOUT, deadline - time.monotonic())
        if budget <= 0:
            return None
        try:
            return self.lifecycle_state(fqn, budget)
        except RosTimeout:
            return None

    def on_transition(self, node: str, callback: Callable[[TransitionEvent], None]) -> None:
        """Call `callback` (in the executor thread) for each `<node>/transition_event`."""
        self._require_running()
        fqn = node_fqn(node)
        with self._lock:
            callbacks = self._transition_callbacks.get(fqn)
            if callbacks is not None:
                callbacks.append(callback)
                return
            self._transition_callbacks[fqn] = [callback]
        self._in_executor(lambda: self._subscribe_transitions(fqn))

    def _subscribe_transitions(self, fqn: str) -> None:
        from lifecycle_msgs.msg import TransitionEvent as TransitionEventMsg

        def deliver(msg: Any) -> None:
            event = TransitionEvent(
                node=fqn,
                transition=msg.transition.label or implied_transition(msg),
                start_state=msg.start_state.label,
                goal_state=msg.goal_state.label,
                transition_id=msg.transition.id,
                received_at=time.monotonic(),
            )
            for callback in list(self._transition_callbacks[fqn]):
                self._guarded(callback, f"{fqn}/transition_event")(event)
            self._notify()

        # rcl_lifecycle publishes with the default QoS (reliable, volatile, depth 10).
        self._node.create_subscription(TransitionEventMsg, f"{fqn}/transition_event", deliver, 10)

    def _client(self, service: str, srv_type: Any) -> Any:
        with self._lock:
            client = self._clients.get(service)
        if client is None:
            client = self._in_executor(lambda: self._node.create_client(srv_type, service))
            with self._lock:
                client = self._clients.setdefault(service, client)
        return client

    def _call(
        self, service: str, srv_type: Any, request: Any, deadline: float, timeout: float
    ) -> Any:
        """Send `request` to `service` and wait for the answer until `deadline`."""
        client = self._client(service, srv_type)
        ready = self.wait_for(lambda _g: client.service_is_ready(), deadline - time.monotonic())
        self._require_running()  # closed meanwhile: say so, not "service not available"
        if not ready:
            self._settling.forget(service)  # a server that comes back settles again
            raise RosTimeout(
                f"service {service} not available within {timeout:g} s: "
                "is the node running, and is it a managed (lifecycle) node?"
            )
        left = self._settling.left(service)  # let the server match our reader (ros.discovery)
        if left > 0:
            self.wait_for(lambda _g: False, min(left, max(0.0, deadline - time.monotonic())))
        call = PendingCall(client.call_async(request), threading.Event())
        call.future.add_done_callback(lambda _f: call.done.set())
        with self._lock:
            self._calls.append(call)
        try:
            call.done.wait(max(0.0, deadline - time.monotonic()))
        finally:
            with self._lock:
                self._calls.remove(call)
        self._require_running()
        if not call.future.done():
            client.remove_pending_request(call.future)
            raise RosTimeout(f"no answer from {service} within {timeout:g} s (did the node die?)")
        return call.future.result()


# -- names, types and QoS ----------------------------------------------------------------------


def parameter_value(value: Any) -> tuple[bool, Any]:
    """(set, the Python value) of an rcl_interfaces ParameterValue (type 0: not set)."""
    fields = {
        1: "bool_value",
        2: "integer_value",
        3: "double_value",
        4: "string_value",
        5: "byte_array_value",
        6: "bool_array_value",
        7: "integer_array_value",
        8: "double_array_value",
        9: "string_array_value",
    }
    field = fields.get(int(value.type))
    if field is None:
        return False, None
    found = getattr(value, field)
    return True, list(found) if field.endswith("array_value") else found


# The names the rest of mlaunch (and launch files' tests) import from the bridge.
__all__ = [
    "INSTALL_HINT",
    "GraphNotRunning",
    "RosBridgeError",
    "RosGraph",
    "RosInputError",
    "RosTimeout",
    "RosUnavailable",
    "TransitionEvent",
    "TransitionResult",
    "domain_id_from",
    "message_class",
    "node_fqn",
]
