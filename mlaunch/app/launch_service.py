"""``launch.LaunchService``: drive launches from Python, on mlaunch's resolver and supervisor.

Scripts written for ROS 2 create a service, include descriptions, call ``run()`` from the main
thread and ``shutdown()`` from anywhere. Here ``run()`` resolves what was included into a Plan
and hands it to mlaunch's Supervisor (with its guard, stop ladder and log folder), so a script
gets the same processes, argv and events as ``mlaunch FILE``.

Nothing outlives the service: ``run()`` ends when everything it started has ended; a cancelled
``run_async`` shuts the launch down first; a threaded run still going when the interpreter
exits is stopped by mlaunch.app.service_exit's exit hook.

Thread safety: ``include_launch_description``, ``emit_event`` and ``shutdown`` may be called
from any thread. While the service runs, they are queued and the supervisor's loop is woken
through a pipe in its own selector; the loop runs them between two turns, so nothing outside
the loop thread ever touches the supervisor.

Return codes of ``run()``: 0 when the launch ended normally; 1 when a description could not be
resolved, an action failed, or a required process failed (ROS 2 returns 0 for the last one;
mlaunch's exit codes say more, on purpose); 128+N when it was stopped by signal N.
"""

from __future__ import annotations

import os
import selectors
import sys
import threading
from collections import deque

from mlaunch.launch.launch_context import LaunchContext
from mlaunch.launch.launch_description import LaunchDescription
from mlaunch.plan.errors import MlaunchError
from mlaunch.plan.records import Said

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable, Coroutine, Iterable
    from typing import Any

    from mlaunch.engine.supervisor import Supervisor
    from mlaunch.plan.steps import Plan
    from mlaunch.resolve.resolver import LabelCounter, ResolveOptions

# A service kept alive when idle re-arms a timer this often (a timer keeps the loop running).
KEEP_ALIVE_PERIOD = 3600.0
# At interpreter exit, how long a threaded run is given to stop before it is SIGKILLed (the
# stop ladder's default SIGINT -> SIGTERM -> SIGKILL takes 10 s at most).
EXIT_WAIT = 15.0


class LaunchService:
    """Runs included launch descriptions until they finish or ``shutdown()`` is called.

    ``argv`` is what the descriptions see as the launch's arguments (``name:=value`` items set
    launch configurations, as on the command line). ``screen`` receives the bytes meant for the
    terminal (None: the real one); it is a seam for tests and embedders.
    """

    def __init__(
        self,
        *,
        argv: Iterable[str] | None = None,
        noninteractive: bool = False,
        debug: bool = False,
        screen: Callable[[bytes], object] | None = None,
    ) -> None:
        self.argv = list(argv or [])
        self.noninteractive = noninteractive
        self.debug = debug
        self.screen = screen
        self._context = LaunchContext(
            environment=os.environ, argv=tuple(self.argv), noninteractive=noninteractive
        )
        for item in self.argv:
            name, sep, value = item.partition(":=")
            if sep and name:
                self._context.launch_configurations[name] = value
        self._pending: list[Any] = []
        self._lock = threading.Lock()
        self._calls: deque[Callable[[], None]] = deque()
        self._supervisor: Supervisor | None = None
        self._labels: LabelCounter | None = None
        self._options: ResolveOptions | None = None
        self._wake_w = -1
        self._running = False
        self._error = False
        self._event_loop: Any = None
        self._thread: threading.Thread | None = None
        self._loop_thread = 0  # the thread of the loop awaiting run_async()
        self.return_code: int | None = None

    # --- the public API of launch.LaunchService ------------------------------------------------

    @property
    def context(self) -> LaunchContext:
        """The context the included descriptions are resolved in (launch configurations...)."""
        return self._context

    def include_launch_description(self, launch_description: Any) -> None:
        """Resolve and run ``launch_description`` (now if running, else when ``run()`` starts)."""
        with self._lock:
            if not self._running:
                self._pending.append(launch_description)
                return
        self._call_soon(lambda: self._include_now(launch_description))

    def emit_event(self, event: Any) -> None:
        """Emit ``event`` as a launch file's EmitEvent would (queued until the service runs).

        ``launch.events.IncludeLaunchDescription`` includes its description.
        """
        from mlaunch.launch.events.include_launch_description import IncludeLaunchDescription

        if isinstance(event, IncludeLaunchDescription):
            self.include_launch_description(event.launch_description)
            return
        from mlaunch.launch.actions.emit_event import EmitEvent

        self.include_launch_description(LaunchDescription([EmitEvent(event=event)]))

    def shutdown(self, force_sync: bool = False) -> Coroutine[Any, Any, None] | None:
        """Shut the running launch down (its processes get the stop ladder); thread-safe.

        Does nothing if the service is not running. ``force_sync`` is accepted for ROS 2
        compatibility: the request is always queued to the loop, which acts on it at once.
        Called from the thread of the asyncio loop awaiting ``run_async()``, it returns a
        coroutine for that loop to await, as ROS 2's does (the request is made already).
        """
        self._request_shutdown("LaunchService.shutdown() called")
        if self._event_loop is None or threading.get_ident() != self._loop_thread:
            return None
        return _requested()

    def run(self, *, shutdown_when_idle: bool = True) -> int:
        """Run everything included until the launch ends; the return code (see the module).

        Must be called from the main thread (signals are handled there), as in ROS 2.
        """
        if threading.current_thread() is not threading.main_thread():
            raise RuntimeError("LaunchService can only be run in the main thread")
        return self._run_checked(shutdown_when_idle)

    def _run_checked(self, shutdown_when_idle: bool, *, claimed: bool = False) -> int:
        with self._lock:
            if self._running and not claimed:
                raise RuntimeError("LaunchService.run() is already running")
            self._running = True
            pending, self._pending = self._pending, []
        try:
            return self._run(pending, shutdown_when_idle)
        finally:
            with self._lock:
                self._running = False
                self._supervisor = None
                self._calls.clear()

    async def run_async(self, *, shutdown_when_idle: bool = True) -> int:
        """``run()`` for callers inside a coroutine, as ROS 2's run_async.

        The launch runs on a thread of its own, so the asyncio loop keeps serving its other
        coroutines meanwhile. mlaunch then installs no signal handlers (the caller's own loop
        owns Ctrl-C: call ``shutdown()`` from it) and notices exits by polling every 50 ms.
        Cancelled (``task.cancel()``, ``asyncio.wait_for`` timing out), the launch is shut down
        as ROS 2's is (its processes get the stop ladder) and, once it has ended, the task
        returns 1 as ROS 2's does; a second cancel SIGKILLs what is left. A task dropped
        unfinished (its loop closed) shuts the launch down too.
        """
        import asyncio
        import weakref

        loop = asyncio.get_running_loop()
        ended: asyncio.Future[int] = loop.create_future()
        # The run's thread holds the future weakly: a task dropped unfinished must be
        # collectable, so that its coroutine is closed and shuts the launch down.
        awaited = weakref.ref(ended)

        def settle(code: int, error: BaseException | None) -> None:
            future = awaited()
            if future is None or future.done():
                return
            if error is not None:
                future.set_exception(error)
            else:
                future.set_result(code)

        def finished(code: int, error: BaseException | None) -> None:
            try:
                loop.call_soon_threadsafe(settle, code, error)
            except RuntimeError:
                pass  # the loop is closed: nobody awaits the result any more

        self._start_thread(shutdown_when_idle, finished)
        self._event_loop = loop
        self._loop_thread = threading.get_ident()
        try:
            return await asyncio.shield(ended)
        except asyncio.CancelledError:
            self._request_shutdown("run task was canceled")
            await self._outlast_cancels(ended)
            return 1
        except GeneratorExit:
            self._request_shutdown("the run_async task was dropped unfinished")
            raise
        finally:
            self._event_loop = None

    async def _outlast_cancels(self, ended: Any) -> None:
        """Wait for a cancelled run to end; a cancel meanwhile SIGKILLs everything at once."""
        import asyncio

        while not ended.done():
            try:
                await asyncio.shield(ended)
            except asyncio.CancelledError:
                self._call_if_running(self._kill_now)
            except Exception:
                return  # the run failed while stopping: a cancelled task returns 1 anyway

    def run_in_thread(self, *, shutdown_when_idle: bool = True) -> threading.Thread:
        """Start the launch on a thread of its own and return it (an mlaunch extension).

        As with ``run_async``, no signal handlers are installed; ``shutdown()`` ends it.
        ``return_code`` holds what ``run()`` would have returned once the thread has ended.
        """
        return self._start_thread(shutdown_when_idle, None)

    def _start_thread(
        self,
        shutdown_when_idle: bool,
        finished: Callable[[int, BaseException | None], None] | None,
    ) -> threading.Thread:
        """Run on a daemon thread (the interpreter does not wait for it at exit: the exit hook
        of mlaunch.app.service_exit stops it); ``finished(code, error)`` is called at its end."""
        from mlaunch.app import service_exit

        with self._lock:
            if self._running:
                raise RuntimeError("LaunchService.run() is already running")
            self._running = True  # now, so a shutdown() right after this call is not lost

        def target() -> None:
            code, error = 1, None
            try:
                code = self._run_checked(shutdown_when_idle, claimed=True)
            except BaseException as e:
                error = e
                if finished is None:
                    raise
            finally:
                self.return_code = code
                service_exit.forget(self)
                if finished is not None:
                    finished(code, error)

        thread = threading.Thread(target=target, name="LaunchService", daemon=True)
        self._thread = thread
        service_exit.watch(self)
        thread.start()
        return thread

    def stop_at_exit(self) -> None:
        """The interpreter exits while the run goes on: stop it and wait for it, bounded."""
        thread = self._thread
        if thread is None or not thread.is_alive():
            return
        self._request_shutdown("the Python interpreter is exiting")
        thread.join(EXIT_WAIT)
        if thread.is_alive():
            self._call_if_running(self._kill_now)
            thread.join(EXIT_WAIT)

    @property
    def event_loop(self) -> Any:
        """The asyncio loop awaiting ``run_async()``; None when the service does not run so."""
        return self._event_loop

    def _is_idle(self) -> bool:
        """Nothing runs and nothing is queued (always true when the service does not run)."""
        supervisor = self._supervisor
        if supervisor is None:
            return True
        return not self._calls and not any(p.running for p in supervisor.processes)

    # --- running --------------------------------------------------------------------------------

    def _run(self, pending: list[Any], shutdown_when_idle: bool) -> int:
        from mlaunch.app.parts import components_part, lifecycle_part, ros_clock_part
        from mlaunch.engine.guard import Guard, new_run_id
        from mlaunch.engine.logfiles import make_run_log_dir
        from mlaunch.engine.output import Printer, stdout_is_color_terminal
        from mlaunch.engine.privatedir import private_temp_dir, remove_private_dir
        from mlaunch.engine.supervisor import Supervisor
        from mlaunch.resolve.resolver import LabelCounter, ResolveOptions

        temp_dir = private_temp_dir()
        guard = None
        printer = None
        wake_r = -1
        try:
            log_dir = make_run_log_dir(os.environ)
            self._context.log_dir = log_dir
            self._options = ResolveOptions(temp_dir=temp_dir)
            self._labels = LabelCounter()
            try:
                plan = self._resolve(LaunchDescription([*self._bookkeeping(), *pending]))
            except MlaunchError as e:
                print(f"mlaunch: error: {e}", file=sys.stderr)
                return 1
            run_id = new_run_id()
            guard = Guard.start(run_id, temp_dir=temp_dir)
            color = self.screen is None and stdout_is_color_terminal(os.environ)
            printer = Printer(out=self.screen, color=color, log_dir=log_dir)
            supervisor = Supervisor(
                plan,
                printer,
                options=self._options,
                labels=self._labels,
                guard=guard,
                run_id=run_id,
                # A script may have children of its own: the run's are found by their marker.
                adopt=False,
                # Its host may raise into the loop (a test runner's timeout): stop gently.
                gentle_on_error=True,
            )
            said = Said("INFO", "launch", f"All log files can be found below {log_dir}")
            supervisor.records.emit(said)
            wake_r, self._wake_w = os.pipe()
            os.set_blocking(wake_r, False)
            os.set_blocking(self._wake_w, False)
            supervisor.selector.register(wake_r, selectors.EVENT_READ, self._run_calls)
            if not shutdown_when_idle:
                self._keep_alive(supervisor)
            with self._lock:
                self._supervisor = supervisor
            if self._calls:
                self._wake()
            # Lifecycle nodes are driven, composable nodes loaded, and ROSTimers on simulated
            # time counted, by the same parts as in ``mlaunch FILE``.
            arguments = dict(i.partition(":=")[::2] for i in self.argv if ":=" in i)
            lifecycle = lambda: lifecycle_part(plan, supervisor, arguments)  # noqa: E731
            supervisor.reactor.attach("lifecycle driving", lifecycle)
            attach = lambda: components_part(plan, supervisor)  # noqa: E731
            supervisor.reactor.attach("the LoadNode driver", attach)
            supervisor.reactor.attach("the ROS clock", lambda: ros_clock_part(supervisor))
            try:
                code = supervisor.run()
            finally:
                supervisor.reactor.close_all()
                # However it ended, the launch has shut down (launch sets it on its Shutdown).
                self._context._set_is_shutdown(True)
            if self._error and code == 0:
                code = 1
            return code
        finally:
            if printer is not None:
                printer.close()
            if guard is not None:
                guard.close()
            for fd in (wake_r, self._wake_w):
                if fd >= 0:
                    os.close(fd)
            self._wake_w = -1
            remove_private_dir(temp_dir)

    def _resolve(self, description: Any) -> Plan:
        """Resolve ``description`` in the service's context (shared by every include)."""
        from mlaunch.plan.steps import Plan
        from mlaunch.resolve.resolver import Resolver

        assert self._options is not None and self._labels is not None
        plan = Plan(temp_dir=self._options.temp_dir)
        self._context._warn = plan.warnings.append
        resolver = Resolver(self._context, plan, labels=self._labels, options=self._options)
        resolver.visit(description)
        return plan

    def _keep_alive(self, supervisor: Supervisor) -> None:
        """A pending timer is what keeps an idle supervisor running; re-arm it forever."""
        supervisor.schedule(KEEP_ALIVE_PERIOD, lambda: self._keep_alive(supervisor))

    def _bookkeeping(self) -> list[Any]:
        """Handlers that give each process action ROS 2's process_details and return_code.

        Registered through the launch API like any launch file's, before what was included (a
        handler sees only the processes started after it), so a launch file's own handler of
        the same start runs first and may not see process_details filled in yet.
        """
        from mlaunch.launch.actions.register_event_handler import RegisterEventHandler
        from mlaunch.launch.event_handlers.on_process_exit import OnProcessExit
        from mlaunch.launch.event_handlers.on_process_start import OnProcessStart

        def started(event: Any, context: Any) -> None:
            if event.action is not None:
                event.action.process_details = {
                    "type": "command",
                    "name": event.name,
                    "cmd": list(event.cmd),
                    "cwd": event.cwd,
                    "env": dict(event.env or {}),
                    "pid": event.pid,
                }

        def exited(event: Any, context: Any) -> None:
            if event.action is not None:
                event.action.return_code = event.returncode

        return [
            RegisterEventHandler(OnProcessStart(on_start=started)),
            RegisterEventHandler(OnProcessExit(on_exit=exited)),
        ]

    # --- calls from other threads ---------------------------------------------------------------

    def _call_soon(self, call: Callable[[], None]) -> None:
        self._calls.append(call)
        self._wake()

    def _wake(self) -> None:
        fd = self._wake_w
        if fd < 0:
            return  # not in the loop yet: run() wakes itself once the supervisor exists
        try:
            os.write(fd, b"!")
        except (BlockingIOError, OSError):
            pass  # a full pipe already wakes the loop; a closed one means the run ended

    def _run_calls(self, fd: int) -> None:
        from mlaunch.engine.signals import drain

        drain(fd)
        while self._calls:
            self._calls.popleft()()

    def _include_now(self, description: Any) -> None:
        supervisor = self._supervisor
        if supervisor is None:
            return
        try:
            plan = self._resolve(description)
        except MlaunchError as e:
            supervisor.records.emit(Said("ERROR", "launch", str(e)))
            self._error = True
            supervisor.begin_shutdown("an included launch description failed")
            return
        for warning in plan.warnings:
            supervisor.records.emit(Said("WARNING", "launch", warning))
        supervisor.execute(plan.steps)

    def _request_shutdown(self, reason: str) -> None:
        """Queue the shutdown of a running launch, ``reason`` its log line; thread-safe.

        The context says ``is_shutdown`` from now on, as launch's does when asked to shut down.
        """
        with self._lock:
            running = self._running
        if running:
            self._context._set_is_shutdown(True)
        self._call_if_running(lambda: self._shutdown_now(reason))

    def _call_if_running(self, call: Callable[[], None]) -> None:
        with self._lock:
            if not self._running:
                return
        self._call_soon(call)

    def _shutdown_now(self, reason: str) -> None:
        if self._supervisor is not None:
            self._supervisor.begin_shutdown(reason)

    def _kill_now(self) -> None:
        """The stop ladder at once (SIGKILL) for a run that must end now."""
        if self._supervisor is not None:
            self._supervisor.kill_everything()


async def _requested() -> None:
    """What ``shutdown()`` gives a caller on the loop: the shutdown is already on its way."""
