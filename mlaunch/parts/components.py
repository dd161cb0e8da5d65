"""The LoadNode driver: sends every ``LoadComponents`` step of a run to its container.

The supervisor hands each LoadComponents step over on the record stream (``HandedOff``) when it
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

The requests go over RTPS from this process itself where that is exactly what rclpy would do
(Fast DDS at its defaults on every side: ``mlaunch.parts.rtps``), else through rclpy
(``mlaunch.parts.loadnode_links``; ``MLAUNCH_LOADER=rclpy`` chooses it). rclpy and
composition_interfaces are imported only for the second.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Mapping

from mlaunch.engine.part import Part
from mlaunch.launch_ros.actions.node import same_name_warning
from mlaunch.launch_ros.composition import LoadComponents
from mlaunch.launch_ros.load_request import LoadRequest
from mlaunch.parts.discovery import Settling
from mlaunch.plan.errors import EXIT_FAILURE, MlaunchError
from mlaunch.plan.records import (
    ComponentLoaded,
    Exited,
    HandedOff,
    LoadRefused,
    Record,
    Said,
    ShutdownBegun,
)
from mlaunch.plan.value import Value

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any, Protocol

    from mlaunch.engine.part import AttachedRun, EndingRun
    from mlaunch.plan.steps import Plan

    class LoadingRun(AttachedRun, EndingRun, Protocol):
        """What the LoadNode driver uses of the run (the Supervisor is one): the plan (its
        processes' environment), and work that keeps an idle run alive (a pending load)."""

        @property
        def plan(self) -> Plan: ...

        def busy(self, work: object) -> None: ...

        def done(self, work: object) -> None: ...


# (level, message): where the driver's lines go (the run's printer, a test's list).
Log = Callable[[str, str], None]
# The logger launch_ros's LoadComposableNodes logs under (its module's name).
LOGGER = "launch_ros.actions.load_composable_nodes"

# How often a wait looks at the container again; a stop ends a wait at once.
POLL = 0.1


class LoadResult(Value):
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


class Component:
    """One composable node of the run, as the launch panel and ``mlaunch ctl unload``/``load``
    see it: its container, its load request, and ``state`` ("loading", "loaded", "failed",
    "not loaded": abandoned at shutdown, "unloading", "unloaded", "gone": its container exited).
    ``name`` is its full name once loaded (the request's until then)."""

    __slots__ = ("error", "name", "request", "state", "step", "unique_id")

    def __init__(self, step: LoadComponents, request: LoadRequest) -> None:
        self.step = step
        self.request = request
        self.state = "loading"
        self.name = request.full_name if request.node_name else ""
        self.unique_id = 0
        self.error = ""

    def as_dict(self) -> dict[str, object]:
        return {
            "container": self.step.target,
            "name": self.name,
            "plugin": self.request.plugin_name,
            "state": self.state,
            "unique_id": self.unique_id,
            "error": self.error,
        }


# How long an unload waits for the container's service and for its answer.
UNLOAD_TIMEOUT = 10.0


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
        link: Any,
        log: Log,
        finished: Callable[[threading.Thread], None] | None = None,
        loaded: Callable[[LoadComponents, str, LoadRequest], None] | None = None,
        failed: Callable[[LoadComponents], None] | None = None,
        refused: Callable[[LoadComponents, LoadResult], None] | None = None,
    ) -> None:
        # how the requests reach the containers (mlaunch.parts.loadnode_links)
        self.link = link
        self.log = log
        self.finished = finished
        # (step, the node's full name, the request) after each successful load
        self.loaded = loaded
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
        # Every composable node the run asked for, in order; each step's, by its count.
        self.components: list[Component] = []
        self._entries: dict[int, list[Component]] = {}

    def listed(self) -> list[dict[str, object]]:
        """Every composable node of the run and its state (any thread)."""
        with self._lock:
            return [c.as_dict() for c in self.components]

    def find(self, name: str) -> Component | None:
        """The composable node ``name`` (its full name, or its name alone when only one has it)."""
        with self._lock:
            named = [c for c in self.components if c.name == name] or [
                c for c in self.components if c.name.rsplit("/", 1)[-1] == name
            ]
            return named[0] if len(named) == 1 else None

    def start(
        self, step: LoadComponents, entries: list[Component] | None = None
    ) -> threading.Thread:
        """Load ``step`` in a new thread (returned, so a caller can join it).

        Its requests are pending from now on (not from when the thread gets going), so a
        container that dies at once is known to have had loads waiting for it.
        """
        with self._lock:
            self._count += 1
            count = self._count
            self._pending[count] = (step.target, list(step.requests))
            if entries is None:
                entries = [Component(step, request) for request in step.requests]
                self.components.extend(entries)
            for entry in entries:
                entry.state, entry.error = "loading", ""
            self._entries[count] = entries
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
                for entry in self._entries.pop(count, []):
                    if entry.state == "loading":
                        entry.state = "not loaded"
            if self.finished is not None:
                self.finished(threading.current_thread())

    def load(self, step: LoadComponents, count: int) -> list[LoadResult]:
        """Send the step's requests in order, each once the container answered the one before.

        Once stopped, each request not sent (or not answered) is abandoned with its own line.
        ``count`` numbers the step (its pending requests).
        """
        with self._lock:
            remaining = self._pending[count][1]
            entries = list(self._entries.get(count, []))
        results: list[LoadResult] = []
        client = None
        try:
            client = self.link.client(step.service, "LoadNode")
            for index, request in enumerate(step.requests):
                result = None
                if self._wait_for_service(client, step, request):
                    result = self._call(client, request, step)
                with self._lock:
                    remaining.pop(0)
                    if result is not None and index < len(entries):
                        _note(entries[index], result)
                if result is not None:
                    results.append(result)
                    with self._lock:
                        self.results.append(result)
        finally:
            if client is not None:
                self.link.destroy(client)
            self._settling.forget(id(client))  # the id may be reused by a later client
        return results

    def prepare(self) -> None:
        """Make the link's participant now, on the calling thread (the run's: see
        mlaunch.parts.lean)."""
        self.link.prepare()

    def close(self) -> None:
        """End the link (the loads have ended)."""
        self.link.close()

    def unload(self, component: Component, done: Callable[[Component], None]) -> None:
        """Ask its container to unload ``component`` (a thread of its own); ``done(component)``
        from that thread once it answered (``error`` set when it did not unload it)."""
        with self._lock:
            if component.state != "loaded":
                raise ValueError(f"{component.name} is {component.state}, not loaded")
            component.state, component.error = "unloading", ""
        thread = threading.Thread(
            target=self._unload, args=(component, done), name="unload", daemon=True
        )
        thread.start()

    def _unload(self, component: Component, done: Callable[[Component], None]) -> None:
        try:
            error = self._unload_call(component)
        except Exception as e:  # an rclpy failure is the answer, not a dead thread
            error = f"{type(e).__name__}: {e}"
        with self._lock:
            component.state, component.error = ("loaded", error) if error else ("unloaded", "")
        if not error:
            self.log(
                "INFO",
                f"Unloaded node '{component.name}' from container"
                f" '{component.step.container_name}'",
            )
        done(component)

    def _unload_call(self, component: Component) -> str:
        """The container's UnloadNode answer: "" when it unloaded the node, else why not."""
        import time

        service = f"{component.step.target}/_container/unload_node"
        client = self.link.client(service, "UnloadNode")
        try:
            deadline = time.monotonic() + UNLOAD_TIMEOUT
            while not self.link.ready(client):
                if self._stopping() or time.monotonic() > deadline:
                    return f"the container does not serve {service}"
                self.stop.wait(POLL)
            response = self.link.call(
                client,
                component.unique_id,
                lambda: self._stopping() or time.monotonic() > deadline,
            )
            if response is None:
                return f"no answer from {service} in {UNLOAD_TIMEOUT:.0f} s"
            return "" if response.success else (response.error_message or "refused")
        finally:
            self.link.destroy(client)

    def reload(self, component: Component) -> threading.Thread:
        """Load ``component`` into its container again (an unloaded or failed one)."""
        with self._lock:
            if component.state not in ("unloaded", "failed", "not loaded"):
                raise ValueError(f"{component.name} is {component.state}")
        step = LoadComponents(
            component.step.origin,
            component.step.target,
            (component.request,),
            component.step.written,
        )
        return self.start(step, [component])

    def container_exited(self, target: str) -> None:
        """The container ``target`` exited: what it had loaded is gone with it."""
        with self._lock:
            for component in self.components:
                if component.step.target == target and component.state in ("loaded", "unloading"):
                    component.state = "gone"

    def _stopping(self) -> bool:
        return self.stop.is_set() or not self.link.ok()

    def _wait_for_service(self, client: Any, step: LoadComponents, request: LoadRequest) -> bool:
        """Wait until the container serves load_node; False (said) once the launch stops."""
        while not self._stopping():
            if self.link.ready(client):
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
        A link that knows the container matched the client does not settle.
        """
        if not self.link.settles:
            return True
        left = self._settling.left(id(client))
        if left > 0:
            self.stop.wait(left)
            return False
        return True

    def _call(self, client: Any, request: LoadRequest, step: LoadComponents) -> LoadResult | None:
        response = self.link.call(client, request, self._stopping)
        if response is None:
            self.log(
                "WARNING",
                f"Abandoning wait for the '{step.service}' service response, due to"
                f" shutdown: {describe_load(request)} may not have been loaded",
            )
            return None
        name = response.full_node_name or request.node_name
        if response.success:
            if self.loaded is not None and name:
                self.loaded(step, name, request)
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


def make_link(environ: Mapping[str, str], processes: list[dict[str, str]], domain: int) -> Any:
    """The RTPS link where it does exactly what rclpy would (mlaunch.parts.rtps.unusable),
    else rclpy's; ``environ`` is the launcher's, ``processes`` the launched processes'."""
    from mlaunch.parts.rtps import discovery_range, unusable

    why = unusable(environ, processes)
    if not why:
        from mlaunch.parts.loadnode_links import RtpsLink

        return RtpsLink(domain, discovery_range(environ) or "SUBNET")
    try:
        import composition_interfaces.srv  # noqa: F401  (the loads need it, say so now)

        from mlaunch.parts.loadnode_links import rclpy_link

        link = rclpy_link(domain)
    except ImportError as e:
        raise MlaunchError(
            f"composable nodes are loaded with rclpy here ({why}), which needs rclpy and"
            f" composition_interfaces ({e}): run ./scripts/setup, or source a ROS 2 installation"
        ) from e
    link.reason = why
    return link


def _describe(link: Any) -> str:
    """How this run's loads are sent (a --debug line)."""
    if link.name == "rtps":
        return f"LoadNode requests go over RTPS (domain {link.domain}, discovery {link.scope})"
    return f"LoadNode requests go through rclpy ({link.reason})"


def _note(component: Component, result: LoadResult) -> None:
    """What the container answered, on the component (the loader's lock held)."""
    if result.success:
        component.state, component.error = "loaded", ""
        component.name = result.full_node_name or component.name
        component.unique_id = result.unique_id
    else:
        component.state, component.error = "failed", result.error_message


# --- attached to a run ---------------------------------------------------------------------


class ComponentDriver(Part):
    """The pipeline's components part: loads each LoadComponents step the supervisor hands over.

    It subscribes to the run's record stream: a ``HandedOff`` LoadComponents starts its loads,
    ``ShutdownBegun`` abandons every wait (as launch_ros at shutdown), the ``Exited`` of a
    container with loads pending is said. Lines go to the run's output from the supervisor's
    loop thread (the printer is not shared across threads).
    """

    def __init__(self, supervisor: LoadingRun) -> None:
        import os

        from mlaunch.parts.graph_types import domain_id_from
        from mlaunch.parts.handoff import LoopCall

        self.supervisor = supervisor
        self.loop = LoopCall(supervisor.selector)
        processes = [dict(s.env) for s in supervisor.plan.processes()]
        environ = processes[0] if processes else dict(os.environ)
        domain = domain_id_from(environ)
        link = make_link(os.environ, processes, domain)
        self.loader = ComponentLoader(
            link, self._log, self._finished, self._loaded, self._failed, self._refused
        )
        # The participant (and rclpy's loader node), here on the run's thread (the lean
        # participant's setting is in os.environ while it is made; no one spawns meanwhile).
        self._say("DEBUG", _describe(link))
        if link.name == "rclpy" and "is not 'rtps' or 'rclpy'" in link.reason:
            self._say("WARNING", f"{link.reason}: loading through rclpy")
        try:
            self.loader.prepare()
        except OSError as e:  # RTPS: no port of the domain free, no UDP at all
            if link.name != "rtps":
                raise
            self._say("WARNING", f"the RTPS loader could not start ({e}): loading through rclpy")
            from mlaunch.parts.rtps import LOADER

            link.close()
            self.loader.link = make_link({LOADER: "rclpy"}, processes, domain)
            self.loader.prepare()
        # Who waits for a load thread to end (a ``load`` asked through runtime control).
        self.waiting: list[Callable[[threading.Thread], None]] = []
        supervisor.records.subscribe(self.on_record)

    def on_record(self, record: Record) -> None:
        if isinstance(record, HandedOff) and isinstance(record.step, LoadComponents):
            record.taken = True
            # Keeps an idle launch running until the loads are done (or the launch stops).
            self.supervisor.busy(self.loader.start(record.step))
        elif isinstance(record, ShutdownBegun):
            self.loader.stop.set()
        elif isinstance(record, Exited):
            self._exited(record)

    def _exited(self, event: Exited) -> None:
        node = event.process.spec.node
        target = node.fully_qualified_name if node is not None else None
        if target is not None:
            self.loader.container_exited(target)
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

    def _loaded(self, step: LoadComponents, name: str, request: LoadRequest) -> None:
        """A component counts among the run's node names, as launch_ros counts it; a second
        node of the same name is warned about (under the container's name, as launch_ros).
        A component to autostart is said on the stream (the lifecycle driver brings it up)."""

        def count() -> None:
            if request.autostart:
                self.supervisor.records.emit(ComponentLoaded(step, request, name))
            if step.names is None:
                return
            step.names[name] = step.names.get(name, 0) + 1
            if step.names[name] > 1:
                warning = same_name_warning(step.names[name], name)
                self.supervisor.records.emit(Said("WARNING", step.container_name, warning))

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
        self.loop.call_soon(lambda: self.supervisor.records.emit(event))

    # --- runtime control (mlaunch.parts.control, loop thread) ----------------------------------

    def listed(self) -> list[dict[str, object]]:
        """Every composable node of the run and its state (any thread)."""
        return self.loader.listed()

    def unload(self, name: str, done: Callable[[dict[str, object]], None]) -> None:
        """Unload the composable node ``name``; ``done(its state)`` on the loop thread."""
        from mlaunch.parts.control import ControlError

        component = self._component(name)
        try:
            self.loader.unload(component, lambda c: self.loop.call_soon(lambda: done(c.as_dict())))
        except ValueError as e:
            raise ControlError(f"cannot unload {name}: {e}") from None

    def load(self, name: str, done: Callable[[dict[str, object]], None]) -> None:
        """Load the composable node ``name`` again; ``done(its state)`` once its container
        answered (on the loop thread)."""
        from mlaunch.parts.control import ControlError

        component = self._component(name)
        try:
            thread = self.loader.reload(component)
        except ValueError as e:
            raise ControlError(f"cannot load {name}: {e}") from None
        self.supervisor.busy(thread)

        def answered(finished: threading.Thread) -> None:
            if finished is thread:
                self.waiting.remove(answered)
                done(component.as_dict())

        self.waiting.append(answered)

    def _component(self, name: str) -> Component:
        from mlaunch.parts.control import UnknownNode

        component = self.loader.find(name)
        if component is None:
            names = [str(c["name"]) for c in self.loader.listed() if c["name"]]
            raise UnknownNode(
                f"no composable node {name!r} in this run, or several (composable nodes:"
                f" {', '.join(names) or 'none'})"
            )
        return component

    def _finished(self, thread: threading.Thread) -> None:
        def finished() -> None:
            self.supervisor.done(thread)
            for waiting in list(self.waiting):
                waiting(thread)

        self.loop.call_soon(finished)

    def _log(self, level: str, message: str) -> None:
        """A line from a load's thread, said from the loop thread."""
        self.loop.call_soon(lambda: self._say(level, message))

    def _say(self, level: str, message: str) -> None:
        self.supervisor.records.emit(Said(level, LOGGER, message))

    def close(self) -> None:
        """At the end of the run: abandon what still waits, end the threads, say their lines."""
        self.loader.stop.set()
        self.loader.join(3.0)
        self.loop.run_pending()  # the loop is over: the abandoned loads' lines are said here
        self.supervisor.records.unsubscribe(self.on_record)
        self.loader.close()
        self.loop.close()
