"""How the LoadNode driver reaches the containers: RTPS itself, or rclpy.

Both links do the same four things for ``mlaunch.parts.components``: a client of a service
(``client(service, kind)``, kind "LoadNode" or "UnloadNode"), whether the service is there
(``ready``), a call that waits for its answer until told to stop (``call``: the container's
``Response``, None when abandoned), and ``close``.

- ``RtpsLink`` (the default where it is exactly what rclpy would do: see
  ``mlaunch.parts.rtps.unusable``): the requests go over ``mlaunch.parts.rtps``, the launcher
  imports neither rclpy nor the message packages (~64 MB of its memory on Autoware's
  planning_simulator). Its readiness knows the container matched the client's reply reader, so
  it needs no settling wait.
- ``RclpyLink``: one hidden node of the launcher (``_mlaunch_loader_<pid>``) and its clients,
  as launch_ros's LoadComposableNodes calls them (``MLAUNCH_LOADER=rclpy``, or whenever the
  middleware is not Fast DDS at its defaults).
"""

from __future__ import annotations

import threading
from collections.abc import Callable

from mlaunch.launch_ros.load_request import LoadRequest
from mlaunch.parts.loadnode_cdr import Response

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

# How often a wait looks at the container again; a stop ends a wait at once.
POLL = 0.1


class RtpsLink:
    """The calls over this process's own RTPS participant (made by ``prepare``)."""

    # The readiness is the container's acknowledgement: no settling wait (mlaunch.parts.discovery)
    settles = False
    name = "rtps"

    def __init__(self, domain: int, scope: str) -> None:
        self.domain = domain
        self.scope = scope
        self._participant: Any = None
        self._closed = False
        self._lock = threading.Lock()

    def prepare(self) -> None:
        self._made()

    def _made(self) -> Any:
        with self._lock:
            if self._closed:
                raise RuntimeError("the launch has ended")
            if self._participant is None:
                import os

                from mlaunch.parts.rtps import Participant

                self._participant = Participant(
                    self.domain, self.scope, f"_mlaunch_loader_{os.getpid()}"
                )
            return self._participant

    def ok(self) -> bool:
        return not self._closed

    def client(self, service: str, kind: str) -> Any:
        return self._made().client(service, kind)

    def destroy(self, client: Any) -> None:
        """Clients are shared by service and live as long as the participant."""

    def ready(self, client: Any) -> bool:
        return bool(self._made().ready(client))

    def call(self, client: Any, request: LoadRequest | int, until: Callable[[], bool]) -> Any:
        from mlaunch.parts import loadnode_cdr

        if isinstance(request, LoadRequest):
            payload, read = loadnode_cdr.load_request(request), loadnode_cdr.load_response
        else:
            payload, read = loadnode_cdr.unload_request(request), loadnode_cdr.unload_response
        data = self._made().call(client, payload, until)
        if data is None:
            return None
        try:
            return read(data)
        except loadnode_cdr.CdrError as e:  # the container's answer, unreadable: a failed load
            return Response(False, f"the container's answer could not be read: {e}")

    def close(self) -> None:
        with self._lock:
            participant, self._participant, self._closed = self._participant, None, True
        if participant is not None:
            participant.close()


class RclpyLink:
    """The calls through rclpy: one node every load and unload of the run goes through."""

    settles = True  # seeing the service does not mean it matched the reply reader
    name = "rclpy"

    def __init__(self, context: Any) -> None:
        self.context = context  # an initialised rclpy Context
        self.reason = ""  # why not RTPS (mlaunch.parts.rtps.unusable)
        # The node every client belongs to and its executor (made at the first load); held
        # by whichever thread spins it, or makes or destroys a client.
        self._shared: tuple[Any, Any] | None = None
        self._spin_lock = threading.Lock()
        self._closed = False

    def prepare(self) -> None:
        """Make the shared node now, on the calling thread, with the launcher's lean
        participant (mlaunch.parts.lean): only the thread that resolves and spawns may call it."""
        from mlaunch.parts.lean import lean_participant

        with lean_participant():
            self._node()

    def ok(self) -> bool:
        return bool(self.context.ok())

    def _node(self) -> Any:
        """The one node every load and unload of the run goes through, and its executor.

        Made at the first load: a node per step cost a few hundred kB and ~1.5 ms each (27 on
        Autoware's planning_simulator). Hidden (a leading '_') and unique to this launcher, so
        it never shows among the launched nodes.
        """
        with self._spin_lock:
            if self._closed:
                raise RuntimeError("the launch has ended")
            if self._shared is None:
                import os

                from rclpy.executors import SingleThreadedExecutor
                from rclpy.node import Node
                from rclpy.parameter import Parameter

                node = Node(
                    f"_mlaunch_loader_{os.getpid()}",
                    context=self.context,
                    use_global_arguments=False,
                    start_parameter_services=False,
                    enable_rosout=False,
                    # As the graph bridge's: no <fqn>/get_type_description among the services.
                    parameter_overrides=[Parameter("start_type_description_service", value=False)],
                )
                executor = SingleThreadedExecutor(context=self.context)
                executor.add_node(node)
                self._shared = (node, executor)
            return self._shared

    def client(self, service: str, kind: str) -> Any:
        """A client of the shared node (made while no thread spins its executor)."""
        from composition_interfaces import srv

        node, _ = self._node()
        with self._spin_lock:
            return node.create_client(getattr(srv, kind), service)

    def destroy(self, client: Any) -> None:
        with self._spin_lock:
            if self._shared is not None:  # else closed: the node went with its clients
                self._shared[0].destroy_client(client)

    def ready(self, client: Any) -> bool:
        return bool(client.service_is_ready())

    def call(self, client: Any, request: LoadRequest | int, until: Callable[[], bool]) -> Any:
        """The answer to ``request`` (a LoadRequest, or the unique id to unload); None once
        ``until()``. Whichever waiting thread finds the executor free spins it, for every
        client's answer; the others wait for their own future's callback."""
        if isinstance(request, LoadRequest):
            from mlaunch.launch_ros.load_request import to_message

            message = to_message(request)
        else:
            from composition_interfaces.srv import UnloadNode

            message = UnloadNode.Request(unique_id=request)
        future = client.call_async(message)
        answered = threading.Event()
        future.add_done_callback(lambda _: answered.set())
        _, executor = self._node()
        while not future.done():
            if until():
                future.cancel()
                return None
            if self._spin_lock.acquire(blocking=False):
                try:
                    executor.spin_once(timeout_sec=POLL)
                finally:
                    self._spin_lock.release()
            else:
                answered.wait(POLL)
        return future.result()

    def close(self) -> None:
        """Destroy the shared node (the loads have ended) and end the context."""
        with self._spin_lock:
            shared, self._shared, self._closed = self._shared, None, True
        if shared is not None:
            node, executor = shared
            executor.shutdown()
            node.destroy_node()
        self.context.try_shutdown()


def rclpy_link(domain: int) -> RclpyLink:
    """An RclpyLink on a context of its own in ``domain`` (ImportError without rclpy)."""
    from rclpy.context import Context

    from mlaunch.parts.lean import limit_arenas

    limit_arenas()  # before rclpy's threads: they share two arenas (mlaunch.parts.lean)
    context = Context()
    context.init([], initialize_logging=False, domain_id=domain)
    return RclpyLink(context)
