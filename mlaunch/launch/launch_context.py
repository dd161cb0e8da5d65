"""The launch context: what substitutions and conditions are evaluated against while resolving.

A run's context (resolve always gives one an environment) owns a copy: SetEnvironmentVariable
changes what later children get, and a scoped group or a deferred action restores or captures it
without touching the launcher process. A context made without one (``LaunchContext()`` in a
script or a unit test of an extension) works on ``os.environ`` itself, as launch's does: what its
actions set is in ``os.environ``, and PopEnvironment restores it in place.
"""

from __future__ import annotations

import os

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable, Mapping, MutableMapping, Sequence
    from typing import Any

    from mlaunch.plan.planner import Planner


# The run's state key that says it is shutting down (resolve sets it as the engine says).
SHUT_DOWN = "is_shutdown"


class Locals:
    """Attribute access to the context locals (``context.locals.event``), as ROS 2 offers.

    A local shadows a global of the same name, as in launch.
    """

    def __init__(self, values: dict[str, Any], globals_: dict[str, Any] | None = None) -> None:
        object.__setattr__(self, "_values", values)
        object.__setattr__(self, "_globals", {} if globals_ is None else globals_)

    def __getattr__(self, name: str) -> Any:
        if name in self._values:
            return self._values[name]
        try:
            return self._globals[name]
        except KeyError:
            raise AttributeError(name) from None

    def __setattr__(self, name: str, value: Any) -> None:
        raise AttributeError(f"locals are read-only; use context.extend_locals({{{name!r}: ...}})")

    def __contains__(self, name: str) -> bool:
        return name in self._values or name in self._globals

    def get(self, name: str, default: Any = None) -> Any:
        if name in self._values:
            return self._values[name]
        return self._globals.get(name, default)


class LaunchContext:
    """Launch configurations, environment and locals, with scopes that can be pushed and popped."""

    def __init__(
        self,
        *,
        environment: Mapping[str, str] | None = None,
        argv: Sequence[str] | None = None,
        noninteractive: bool = False,
        log_dir: str = "",
        warn: Callable[[str], None] | None = None,
        planner: Planner | None = None,
    ) -> None:
        self.launch_configurations: dict[str, Any] = {}
        # A copy of what the caller gives (resolve always does); else os.environ itself, as launch.
        self._environment: MutableMapping[str, str] = (
            dict(environment) if environment is not None else os.environ
        )
        self.initial_environment: dict[str, str] = dict(self._environment)
        self.argv: list[str] = list(argv or ())
        self.noninteractive = noninteractive
        self.log_dir = log_dir
        self._locals: dict[str, Any] = {}
        self._locals_stack: list[dict[str, Any]] = []
        self._configurations_stack: list[dict[str, Any]] = []
        # Handlers registered through this context (upstream's list: newest first).
        self._event_handlers: list[Any] = []
        self._asyncio_loop: Any = None
        # One run's globals: shared (not copied) by every snapshot, so what a deferred action
        # adds (launch_ros's count of node names) is seen by the whole run.
        self._globals: dict[str, Any] = {}
        # One run's own state (the declared machines ...): shared by every snapshot, like the
        # globals, but not visible to launch-file code through ``locals``.
        self.run_state: dict[str, Any] = {}
        self._scopes: list[tuple[dict[str, Any], dict[str, str]]] = []
        self._warn = warn
        self._planner = planner
        self._events: Any = None  # the asyncio.Queue of _event_queue, made when first asked for

    @property
    def environment(self) -> MutableMapping[str, str]:
        """The environment children get: a copy of the run's, or ``os.environ`` when not given."""
        return self._environment

    @environment.setter
    def environment(self, value: Mapping[str, str]) -> None:
        if self._environment is os.environ:
            if value is not os.environ:
                # In place, as launch restores os.environ: a copy first, value may be a view of it.
                values = dict(value)
                os.environ.clear()
                os.environ.update(values)
        else:
            self._environment = dict(value)

    # --- the seam to planning (mlaunch.plan.planner) ----------------------------------------

    @property
    def planner(self) -> Planner:
        """What turns the actions visited with this context into plan steps.

        Resolve sets its own; a context made without one (an action visited on its own, as unit
        tests of extensions do) gets a standalone planner that collects the steps.
        """
        if self._planner is None:
            from mlaunch.launch.planning import StandalonePlanner

            self._planner = StandalonePlanner(self)
        return self._planner

    @planner.setter
    def planner(self, planner: Planner | None) -> None:
        self._planner = planner

    # --- what ROS 2 launch files use -------------------------------------------------------

    @property
    def locals(self) -> Locals:
        return Locals(self._locals, self._globals)

    def get_locals_as_dict(self) -> dict[str, Any]:
        return {**self._globals, **self._locals}

    def get_locals_as_dict_of_scope(self) -> dict[str, Any]:
        """The locals of this context alone (the run's globals left out)."""
        return dict(self._locals)

    def extend_locals(self, values: Mapping[str, Any]) -> None:
        self._locals.update(values)

    def extend_globals(self, values: Mapping[str, Any]) -> None:
        """Names visible through ``locals`` everywhere in this run, as launch's globals."""
        self._globals.update(values)

    def perform_substitution(self, substitution: Any) -> str:
        from mlaunch.launch.substitution import perform

        return perform(self, substitution)

    def _push_locals(self) -> None:
        self._locals_stack.append(dict(self._locals))

    def _pop_locals(self) -> None:
        if not self._locals_stack:
            raise RuntimeError("locals stack unexpectedly empty")
        self._locals = self._locals_stack.pop()

    def _push_launch_configurations(self) -> None:
        self._configurations_stack.append(dict(self.launch_configurations))

    def _pop_launch_configurations(self) -> None:
        if not self._configurations_stack:
            raise RuntimeError("launch configurations stack unexpectedly empty")
        self.launch_configurations = self._configurations_stack.pop()

    # --- events, handlers, the loop (their effect is a plan step: mlaunch.launch.planning) --

    @property
    def asyncio_loop(self) -> Any:
        """The loop of the run when one is running it, else None (as upstream's bare context)."""
        return self._asyncio_loop

    def _set_asyncio_loop(self, loop: Any) -> None:
        self._asyncio_loop = loop

    @property
    def is_shutdown(self) -> bool:
        """Whether the run is shutting down (said by every context of the run, snapshots too)."""
        return bool(self.run_state.get(SHUT_DOWN))

    def _set_is_shutdown(self, state: bool) -> None:
        self.run_state[SHUT_DOWN] = state

    def register_event_handler(self, event_handler: Any, append: bool = False) -> None:
        """Listen with ``event_handler`` from now on (first in line unless ``append``)."""
        from mlaunch.launch.event_handler import register_step

        if append:
            self._event_handlers.append(event_handler)
        else:
            self._event_handlers.insert(0, event_handler)
        step = register_step(self, event_handler, getattr(event_handler, "origin", ""))
        if step is not None:
            self.planner.add(step)

    def unregister_event_handler(self, event_handler: Any) -> None:
        """Stop ``event_handler``; ValueError when it was not registered here."""
        from mlaunch.plan.steps import RemoveHandler

        self._event_handlers.remove(event_handler)  # ValueError when absent, as upstream
        self.planner.add(RemoveHandler(origin="", handler=event_handler))

    def would_handle_event(self, event: Any) -> bool:
        """Whether a handler registered here matches ``event``."""
        return any(handler.matches(event) for handler in self._event_handlers)

    def emit_event_sync(self, event: Any) -> None:
        """Emit ``event`` when the plan reaches this point (a Shutdown shuts the run down).

        A context that no run plans also holds the event in ``_event_queue``, as upstream's.
        """
        from mlaunch.launch.emission import emit_event_entities

        more = emit_event_entities(self, event, "")
        if more:
            self.planner.visit_all(more)

    async def emit_event(self, event: Any) -> None:
        """``emit_event_sync`` for coroutines, as upstream's awaitable spelling (the queue is
        unbounded: putting never waits)."""
        self.emit_event_sync(event)

    @property
    def _event_queue(self) -> Any:
        """The events given to this context while no run plans it (an ``asyncio.Queue``, as
        upstream's): a standalone planner puts them here, since nothing will emit its steps.
        A run's events are steps of its plan and never pass through this queue."""
        if self._events is None:
            import asyncio  # only a context that no run plans gets here: not at start-up

            self._events = asyncio.Queue()
        return self._events

    @property
    def current_launch_file_path(self) -> str | None:
        return self._locals.get("current_launch_file_path")

    def warn(self, message: str) -> None:
        if self._warn is not None:
            self._warn(message)

    # --- scopes ------------------------------------------------------------------------------

    def push_scope(self) -> None:
        self._scopes.append((dict(self.launch_configurations), dict(self.environment)))

    def pop_scope(self) -> None:
        configs, env = self._scopes.pop()
        self.launch_configurations = configs
        self.environment = env

    def shared_with_outer_scope(self, value: Any) -> bool:
        """Whether ``value`` (a list in the configurations) is also an enclosing scope's."""
        return any(value is v for configs, _ in self._scopes for v in configs.values())

    def lend(self, values: Mapping[str, Any], warn: Callable[[str], None] | None) -> _Lent:
        """``with context.lend(values, warn):`` the context as a timer's or a handler's body is
        visited with it: ``values`` as its locals, its warnings to ``warn``; its own locals,
        warnings and planner are back after (the run's live context, under launch's rule)."""
        return _Lent(self, dict(values), warn)

    def file_locals(self, path: str) -> _FileLocals:
        """Locals of an included file: ThisLaunchFile and friends point at it inside."""
        return _FileLocals(self, path)

    def snapshot(self) -> LaunchContext:
        """A copy frozen now, for actions resolved later (timers, event handlers).

        Capturing at registration fixes ROS 2's L#501: a LaunchConfiguration inside on_exit takes
        the value it had where it was written, not whatever was set last.
        """
        copy = LaunchContext(
            environment=self.environment,
            argv=self.argv,
            noninteractive=self.noninteractive,
            log_dir=self.log_dir,
            warn=self._warn,
        )
        copy.initial_environment = self.initial_environment
        # Lists (launch_ros's global parameters, extended in place as in launch) are copied too.
        copy.launch_configurations = {
            k: list(v) if isinstance(v, list) else v for k, v in self.launch_configurations.items()
        }
        copy._locals = dict(self._locals)
        copy._globals = self._globals
        copy.run_state = self.run_state
        return copy


# A context manager as a small class: contextlib costs ~0.7 ms to import at start-up.


class _FileLocals:
    """``with context.file_locals(path)``: the file's locals inside, the previous ones after."""

    __slots__ = ("context", "path", "saved")

    def __init__(self, context: LaunchContext, path: str) -> None:
        self.context = context
        self.path = path
        self.saved: dict[str, Any] = {}

    def __enter__(self) -> None:
        values = self.context._locals
        self.saved = dict(values)
        values["current_launch_file_path"] = self.path
        values["current_launch_file_directory"] = os.path.dirname(self.path)

    def __exit__(self, *exc_info: object) -> None:
        self.context._locals = self.saved


class _Lent:
    """``with context.lend(values, warn)`` (see ``LaunchContext.lend``)."""

    __slots__ = ("context", "saved", "values", "warn")

    def __init__(
        self, context: LaunchContext, values: dict[str, Any], warn: Callable[[str], None] | None
    ) -> None:
        self.context = context
        self.values = values
        self.warn = warn
        self.saved: tuple[Any, ...] = ()

    def __enter__(self) -> LaunchContext:
        context = self.context
        self.saved = (context._locals, context._warn, context._planner)
        context._locals, context._warn = self.values, self.warn
        return context

    def __exit__(self, *exc_info: object) -> None:
        context = self.context
        context._locals, context._warn, context._planner = self.saved
