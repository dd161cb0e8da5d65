"""The LoadNode driver: sends every ``LoadComponents`` step of a run to its container.

The supervisor hands each LoadComponents step over on the event stream (``HandedOff``) when it
reaches it: in the plan, in a timer's body, in an event handler's (a ComposableNodeContainer
started by OnProcessStart, a LoadComposableNodes in a TimerAction), so every load goes through
this one path, in the order the steps are reached.

As launch_ros does it: each step runs in its own thread (one container that never comes up
does not hold the others back); for each request in order, wait until
``<container>/_container/load_node`` is available, send it, wait for the answer, then the next;
a load that fails is logged with the container's error message and the next one is still sent.
A pending load keeps an otherwise idle launch running (launch's completion futures); a dead
container's loads wait for it to serve again. When the launch shuts down every wait is
abandoned, one line per load never made, and the threads end before the run does. A load that
raises ends the launch with status 1, as launch's run loop does with the exception.

rclpy and composition_interfaces are imported only when a driver is made.
"""

from __future__ import annotations

import threading
from collections.abc import Callable

from mlaunch.engine.part import Part
from mlaunch.launch_ros.composition import LoadComponents
from mlaunch.launch_ros.load_request import LoadRequest, to_message
from mlaunch.launch_ros.node import same_name_warning
from mlaunch.parts.discovery import Settling
from mlaunch.plan.errors import EXIT_FAILURE, MlaunchError
from mlaunch.plan.events import Event, Exited, HandedOff, LoadRefused, Said, ShutdownBegun
from mlaunch.plan.record import Record

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.engine.supervisor import Supervisor

# (level, message): where the driver's lines go (the run's printer, a test's list).
Log = Callable[[str, str], None]
# The logger launch_ros's LoadComposableNodes logs under (its module's name).
LOGGER = "launch_ros.actions.load_composable_nodes"

# How often a wait looks at the container again; a stop ends a wait at once.
POLL = 0.1


class LoadResult(Record):
    """What a container answered to one request."""

    _fields = ("request", "success", "full_node_name", "unique_id", "error_message")
    __slots__ = _fields

    def __init__(
        self,
        request: LoadRequest,
        success: bool,
        full_node_name: str = "",
        unique_id: int = 0,
        error_message: str = "",
    ) -> None:
        self.request = request
        self.success = success
        self.full_node_name = full_node_name
        self.unique_id = unique_id
        self.error_message = error_message


def describe_load(request: LoadRequest) -> str:
    """``node 'talker' of type 'composition::Talker'`` (the plugin alone when it is unnamed)."""
    if request.node_name:
        return f"node '{request.node_name}' of type '{request.plugin_name}'"
    return f"a node of type '{request.plugin_name}'"


class ComponentLoader:
    """Loads steps into containers from threads; ``stop`` ends every wait.

    ``finished(thread)`` is called from a step's thread when it has ended.
    """

    def __init__(
        self,
        context: Any,
        log: Log,
        finished: Callable[[threading.Thread], None] | None = None,
        loaded: Callable[[LoadComponents, str], None] | None = None,
        failed: Callable[[LoadComponents], None] | None = None,
        refused: Callable[[LoadComponents, LoadResult], None] | None = None,
    ) -> None:
        self.context = context  # an initialised rclpy Context
        self.log = log
        self.finished = finished
        self.loaded = loaded  # (step, the node's full name) after each successful load
        self.failed = failed  # (step) when sending its requests raised
        self.refused = refused  # (step, result) when the container answered it did not load
        self.stop = threading.Event()
        self.results: list[LoadResult] = []
        self._threads: list[threading.Thread] = []
        self._lock = threading.Lock()
        self._count = 0
        # The requests of each running step not answered yet, first one next.
        self._pending: dict[int, tuple[str, list[LoadRequest]]] = {}
        # When each client (by id) first saw its service (mlaunch.parts.discovery).
        self._settling = Settling()

    def start(self, step: LoadComponents) -> threading.Thread:
        """Load ``step`` in a new thread (returned, so a caller can join it).

        Its requests are pending from now on (not from when the thread gets going), so a
        container that dies at once is known to have had loads waiting for it.
        """
        with self._lock:
            self._count += 1
            count = self._count
            self._pending[count] = (step.target, list(step.requests))
        thread = threading.Thread(
            target=self._run, args=(step, count), name=f"load {step.target}", daemon=True
        )
        # Ended threads are forgotten: a long run with many loads keeps only the live ones.
        self._threads = [t for t in self._threads if t.is_alive()]
        self._threads.append(thread)
        thread.start()
        return thread

    def join(self, timeout: float) -> bool:
        """Wait for every started step; False when one is still waiting at ``timeout``."""
        import time

        deadline = time.monotonic() + timeout
        for thread in self._threads:
            thread.join(max(0.0, deadline - time.monotonic()))
        return not any(t.is_alive() for t in self._threads)

    def pending(self, target: str) -> list[LoadRequest]:
        """The requests for container ``target`` not answered yet, in the order they go out."""
        with self._lock:
            return [r for t, requests in self._pending.values() if t == target for r in requests]

    def _run(self, step: LoadComponents, count: int) -> None:
        try:
            self.load(step, count)
        except Exception as e:  # a failing rclpy call must not end the thread in silence
            self.log("ERROR", f"Loading into container '{step.container_name}' failed: {e}")
            if self.failed is not None:
                self.failed(step)
        finally:
            with self._lock:
                self._pending.pop(count, None)
            if self.finished is not None:
                self.finished(threading.current_thread())

    def load(self, step: LoadComponents, count: int) -> list[LoadResult]:
        """Send the step's requests in order, each once the container answered the one before.

        Once stopped, each request not sent (or not answered) is abandoned with its own line.
        ``count`` numbers the step (its pending requests and its loader node's name).
        """
        import os

        from composition_interfaces.srv import LoadNode
        from rclpy.node import Node

        with self._lock:
            remaining = self._pending[count][1]
        # Hidden (leading '_') and unique, so it never shows among the launched nodes.
        node = Node(
            f"_mlaunch_loader_{os.getpid()}_{count}",
            context=self.context,
            use_global_arguments=False,
            start_parameter_services=False,
            enable_rosout=False,
        )
        results: list[LoadResult] = []
        client = None
        try:
            client = node.create_client(LoadNode, step.service)
            for request in step.requests:
                result = None
                if self._wait_for_service(client, step, request):
                    result = self._call(node, client, request, step)
                with self._lock:
                    remaining.pop(0)
                if result is not None:
                    results.append(result)
                    with self._lock:
                        self.results.append(result)
        finally:
            node.destroy_node()
            self._settling.forget(id(client))  # the id may be reused by a later client
        return results

    def _stopping(self) -> bool:
        return self.stop.is_set() or not self.context.ok()

    def _wait_for_service(self, client: Any, step: LoadComponents, request: LoadRequest) -> bool:
        """Wait until the container serves load_node; False (said) once the launch stops."""
        while not self._stopping():
            if client.service_is_ready():
                if self._settled(client):
                    return True
                continue
            self._settling.forget(id(client))  # a container that comes back settles again
            self.stop.wait(POLL)
        self.log(
            "WARNING",
            f"Abandoning wait for the '{step.service}' service, due to shutdown:"
            f" {describe_load(request)} was never loaded",
        )
        return False

    def _settled(self, client: Any) -> bool:
        """True once ``client`` has seen its service long enough (mlaunch.parts.discovery).

        Waits out what is left (a stop ends the wait at once); later requests go at once.
        """
        left = self._settling.left(id(client))
        if left > 0:
            self.stop.wait(left)
            return False
        return True

    def _call(
        self, node: Any, client: Any, request: LoadRequest, step: LoadComponents
    ) -> LoadResult | None:
        from rclpy.executors import SingleThreadedExecutor

        future = client.call_async(to_message(request))
        executor = SingleThreadedExecutor(context=self.context)
        executor.add_node(node)
        try:
            while not future.done():
                if self._stopping():
                    self.log(
                        "WARNING",
                        f"Abandoning wait for the '{step.service}' service response, due to"
                        f" shutdown: {describe_load(request)} may not have been loaded",
                    )
                    future.cancel()
                    return None
                executor.spin_once(timeout_sec=POLL)
        finally:
            executor.remove_node(node)
            executor.shutdown()
        response = future.result()
        name = response.full_node_name or request.node_name
        if response.success:
            if self.loaded is not None and name:
                self.loaded(step, name)
            self.log(
                "INFO",
                f"Loaded node '{response.full_node_name}' in container '{step.container_name}'",
            )
        else:
            self.log(
                "ERROR",
                f"Failed to load node '{name}' of type '{request.plugin_name}' in container"
                f" '{step.container_name}': {response.error_message}",
            )
        result = LoadResult(
            request,
            bool(response.success),
            response.full_node_name,
            int(response.unique_id),
            response.error_message,
        )
        if not response.success and self.refused is not None:
            self.refused(step, result)
        return result


# --- attached to a run ---------------------------------------------------------------------


class ComponentDriver(Part):
    """The pipeline's components part: loads each LoadComponents step the supervisor hands over.

    It subscribes to the run's event stream: a ``HandedOff`` LoadComponents starts its loads,
    ``ShutdownBegun`` abandons every wait (as launch_ros at shutdown), the ``Exited`` of a
    container with loads pending is said. Lines go to the run's output from the supervisor's
    loop thread (the printer is not shared across threads).
    """

    def __init__(self, supervisor: Supervisor) -> None:
        import os

        from mlaunch.parts.graph_types import domain_id_from
        from mlaunch.parts.handoff import LoopCall

        try:
            import composition_interfaces.srv  # noqa: F401  (the loads need it, say so now)
            from rclpy.context import Context
        except ImportError as e:
            raise MlaunchError(
                f"composable nodes are loaded with rclpy and composition_interfaces ({e}):"
                " run ./scripts/setup, or source a ROS 2 installation"
            ) from e
        self.supervisor = supervisor
        self.loop = LoopCall(supervisor.selector)
        environ = next((dict(s.env) for s in supervisor.plan.processes()), dict(os.environ))
        context = Context()
        context.init([], initialize_logging=False, domain_id=domain_id_from(environ))
        self.loader = ComponentLoader(
            context, self._log, self._finished, self._loaded, self._failed, self._refused
        )
        supervisor.events.subscribe(self.on_event)

    def on_event(self, event: Event) -> None:
        if isinstance(event, HandedOff) and isinstance(event.step, LoadComponents):
            event.taken = True
            # Keeps an idle launch running until the loads are done (or the launch stops).
            self.supervisor.busy(self.loader.start(event.step))
        elif isinstance(event, ShutdownBegun):
            self.loader.stop.set()
        elif isinstance(event, Exited):
            self._exited(event)

    def _exited(self, event: Exited) -> None:
        node = event.process.spec.node
        target = node.fully_qualified_name if node is not None else None
        if target is None or self.supervisor.shutting_down:
            return
        pending = self.loader.pending(target)
        if not pending:
            return
        loads = ", ".join(describe_load(r) for r in pending)
        self._say(
            "WARNING",
            f"container '{target}' exited before it loaded {loads}: the loads wait for its"
            f" '{target}/_container/load_node' service until the launch stops (as launch_ros)",
        )

    def _loaded(self, step: LoadComponents, name: str) -> None:
        """A component counts among the run's node names, as launch_ros counts it; a second
        node of the same name is warned about (under the container's name, as launch_ros)."""

        def count() -> None:
            if step.names is None:
                return
            step.names[name] = step.names.get(name, 0) + 1
            if step.names[name] > 1:
                warning = same_name_warning(step.names[name], name)
                self.supervisor.events.emit(Said("WARNING", step.container_name, warning))

        self.loop.call_soon(count)  # the count is the loop thread's, as resolve's

    def _failed(self, step: LoadComponents) -> None:
        """A load raised (a value the message cannot carry, an rclpy failure): as launch, whose
        run loop catches the exception, the launch shuts down and exits 1."""

        def fail() -> None:
            supervisor = self.supervisor
            supervisor.exit_status(EXIT_FAILURE)
            supervisor.begin_shutdown(f"loading into container '{step.container_name}' failed")

        self.loop.call_soon(fail)

    def _refused(self, step: LoadComponents, result: LoadResult) -> None:
        """A container refused a load: said on the stream (``mlaunch test`` fails at once; a
        run goes on, as launch_ros's)."""
        request = result.request
        node = request.full_name if request.node_name else request.plugin_name
        event = LoadRefused(step.target, node, request.plugin_name, result.error_message)
        self.loop.call_soon(lambda: self.supervisor.events.emit(event))

    def _finished(self, thread: threading.Thread) -> None:
        self.loop.call_soon(lambda: self.supervisor.done(thread))

    def _log(self, level: str, message: str) -> None:
        """A line from a load's thread, said from the loop thread."""
        self.loop.call_soon(lambda: self._say(level, message))

    def _say(self, level: str, message: str) -> None:
        self.supervisor.events.emit(Said(level, LOGGER, message))

    def close(self) -> None:
        """At the end of the run: abandon what still waits, end the threads, say their lines."""
        self.loader.stop.set()
        self.loader.join(3.0)
        self.loop.run_pending()  # the loop is over: the abandoned loads' lines are said here
        self.supervisor.events.unsubscribe(self.on_event)
        self.loader.context.try_shutdown()
        self.loop.close()
