"""The LoadNode driver: sends a run's ``LoadComponents`` steps to their containers.

As launch_ros does it: for each step, wait until ``<container>/_container/load_node`` is
available (rechecking every second, giving up when the run stops), then send the requests one
after the other, each once the previous one was answered; a load that fails is logged with the
container's error message and the next one is still sent. Each step runs in its own thread
with its own rclpy node, so one container that never comes up does not hold the others back.

rclpy and composition_interfaces are imported only when a driver is made.
"""

from __future__ import annotations

import threading
from collections.abc import Callable

from mlaunch.launch_ros.composition import LoadComponents
from mlaunch.launch_ros.load_request import LoadRequest, to_message
from mlaunch.record import Record

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

# (level, message): where the driver's lines go (the run's printer, a test's list).
Log = Callable[[str, str], None]
# The logger launch_ros's LoadComposableNodes logs under (its module's name).
LOGGER = "launch_ros.actions.load_composable_nodes"


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


class ComponentLoader:
    """Loads steps into containers from threads; ``stop`` ends every wait."""

    def __init__(self, context: Any, log: Log) -> None:
        self.context = context  # an initialised rclpy Context
        self.log = log
        self.stop = threading.Event()
        self.results: list[LoadResult] = []
        self._threads: list[threading.Thread] = []
        self._lock = threading.Lock()
        self._count = 0

    def start(self, step: LoadComponents) -> threading.Thread:
        """Load ``step`` in a new thread (returned, so a caller can join it)."""
        thread = threading.Thread(
            target=self.load, args=(step,), name=f"load {step.target}", daemon=True
        )
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

    def load(self, step: LoadComponents) -> list[LoadResult]:
        """Send the step's requests in order, each once the container answered the one before."""
        import os

        from composition_interfaces.srv import LoadNode
        from rclpy.node import Node

        with self._lock:
            self._count += 1
            count = self._count
        # Hidden (leading '_') and unique, so it never shows among the launched nodes.
        node = Node(
            f"_mlaunch_loader_{os.getpid()}_{count}",
            context=self.context,
            use_global_arguments=False,
            start_parameter_services=False,
            enable_rosout=False,
        )
        results: list[LoadResult] = []
        try:
            client = node.create_client(LoadNode, step.service)
            while not client.wait_for_service(timeout_sec=1.0):
                if self.stop.is_set() or not self.context.ok():
                    self.log("WARNING", f"Abandoning wait for the '{step.service}' service")
                    return results
            for request in step.requests:
                result = self._call(node, client, request, step)
                if result is None:
                    return results
                results.append(result)
                with self._lock:
                    self.results.append(result)
        finally:
            node.destroy_node()
        return results

    def _call(
        self, node: Any, client: Any, request: LoadRequest, step: LoadComponents
    ) -> LoadResult | None:
        from rclpy.executors import SingleThreadedExecutor

        future = client.call_async(to_message(request))
        executor = SingleThreadedExecutor(context=self.context)
        executor.add_node(node)
        try:
            while not future.done():
                if self.stop.is_set() or not self.context.ok():
                    self.log(
                        "WARNING",
                        f"Abandoning wait for the '{step.service}' service response",
                    )
                    future.cancel()
                    return None
                executor.spin_once(timeout_sec=0.1)
        finally:
            executor.remove_node(node)
            executor.shutdown()
        response = future.result()
        name = response.full_node_name or request.node_name
        if response.success:
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
        return LoadResult(
            request,
            bool(response.success),
            response.full_node_name,
            int(response.unique_id),
            response.error_message,
        )


# --- attached to a run ---------------------------------------------------------------------


class ComponentDriver:
    """The pipeline's components part: loads the plan's LoadComponents steps once the run starts.

    Lines go to the run's output from the supervisor's loop thread (the printer is not shared
    across threads). Loads of deferred parts (a LoadComposableNodes in a timer or an event
    handler) are not driven yet: the supervisor runs those steps without telling its parts.
    """

    def __init__(self, supervisor: Any, steps: list[LoadComponents]) -> None:
        import os

        from mlaunch.ros.bridge import domain_id_from
        from mlaunch.ros.lifecycle import LoopCall

        self.supervisor = supervisor
        self.loop = LoopCall(supervisor.selector)
        environ = next((dict(s.env) for s in supervisor.plan.processes()), dict(os.environ))
        from rclpy.context import Context

        context = Context()
        context.init([], initialize_logging=False, domain_id=domain_id_from(environ))
        self.loader = ComponentLoader(context, self._log)
        self.steps = steps
        supervisor.schedule(0.0, self._start, keeps_alive=False)

    def _start(self) -> None:
        for step in self.steps:
            self.loader.start(step)

    def _log(self, level: str, message: str) -> None:
        printer = self.supervisor.printer
        self.loop.call_soon(lambda: printer.message(level, LOGGER, message))

    def close(self) -> None:
        self.loader.stop.set()
        self.loader.join(3.0)
        self.loader.context.try_shutdown()
        self.loop.close()


def attach(options: Any, supervisor: Any) -> ComponentDriver | None:
    """The pipeline's components part: a driver when the plan loads composable nodes, else None."""
    steps = [s for s in supervisor.plan.steps if isinstance(s, LoadComponents)]
    if not steps:
        return None
    return ComponentDriver(supervisor, steps)
