"""``launch.event_handler``: ``EventHandler``, the base of every handler, and how a handler
becomes a step of the plan.

Handlers are data. RegisterEventHandler turns one into an AddHandler step of the plan; the
supervisor fires it and resolves its entities with the context captured at registration.
"""

from __future__ import annotations

from collections.abc import Iterable

from mlaunch.plan.origin import caller_origin
from mlaunch.plan.steps import AddHandler

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable
    from typing import Any


def _as_entities(value: Any) -> tuple[list[Any], Callable[..., Any] | None]:
    """Split ``on_*`` into entities or a callable(event, context) -> entities (a callable
    first, as launch: no launch entity is callable)."""
    if value is None:
        return [], None
    if callable(value) and not isinstance(value, type):
        return [], value
    if isinstance(value, Iterable) and not isinstance(value, (str, bytes)):
        return list(value), None
    return [value], None


def _is_predicate(target: Any) -> bool:
    """A target given as a function of the action: launch tries this before identity."""
    return callable(target)


def check_target(target: Any, handler: str, target_class: type, what: str) -> None:
    """launch's TypeError for a target that is neither ``target_class``, a callable nor None."""
    if target is None or callable(target) or isinstance(target, target_class):
        return
    raise TypeError(
        f"{handler}: target_action must be {what} or a callable, got"
        f" {type(target).__name__}: {target!r:.60}"
    )


def returned_entities(result: Any) -> list[Any]:
    """What a handler callable returned, as launch accepts it: None, one entity, or an iterable
    of entities (Nones in it skipped)."""
    if result is None:
        return []
    if isinstance(result, Iterable) and not isinstance(result, (str, bytes)):
        return [entity for entity in result if entity is not None]
    return [result]


class EventHandler:
    """Base handler: ``kind`` names the event, ``target_action`` narrows it to one action."""

    kind = ""

    def __init__(
        self,
        *,
        target_action: Any = None,
        entities: Any = None,
        handle_once: bool = False,
        matcher: Callable[[Any], bool] | None = None,
    ) -> None:
        self.target_action = target_action
        self.entities, self.callback = _as_entities(entities)
        self.handle_once = handle_once
        self.custom_matcher = matcher
        self.origin = caller_origin()

    def process_matcher(self) -> Callable[[Any], bool] | None:
        """A predicate over ProcessSpec; None matches every process."""
        target = self.target_action
        if target is None:
            return self.custom_matcher
        if _is_predicate(target):
            return _ActionMatches(target)
        return _ActionIs(target)

    def describe_short(self) -> str:
        return type(self).__name__

    # --- upstream's handler API (launch.event_handler), for code that calls handlers itself --

    def event_type(self) -> type | None:
        """The event class this handler's kind listens for (None: only its matcher decides)."""
        return None

    def matches(self, event: Any) -> bool:
        """Whether this handler handles ``event``: its matcher, or its kind and target."""
        if self.custom_matcher is not None:
            return bool(self.custom_matcher(event))
        event_type = self.event_type()
        if event_type is None or not isinstance(event, event_type):
            return False
        target = self.target_action
        if target is None:
            return True
        action = getattr(event, "action", None)
        if _is_predicate(target):
            return bool(target(action))
        return action is target

    def handle(self, event: Any, context: Any) -> list[Any] | None:
        """``event`` becomes ``context.locals.event``; the entities to visit for it."""
        self._begin_handling(event, context)
        if self.callback is not None:
            return returned_entities(self.callback(event, context))
        return list(self.entities)

    def _begin_handling(self, event: Any, context: Any) -> None:
        context.extend_locals({"event": event})
        if self.handle_once:
            context.unregister_event_handler(self)

    @property
    def handler_description(self) -> str | None:
        return None

    @property
    def matcher_description(self) -> str | None:
        return None

    def describe(self) -> tuple[str, list[Any]]:
        """launch's description: a line about the handler, then its entities."""
        text = (
            f"{type(self).__name__}(matcher='{self.matcher_description}',"
            f" handler='{self.handler_description}', handle_once={self.handle_once})"
        )
        return text, list(self.entities)


# The run's state key set once an OnExecutionComplete handler was registered: from then on
# every action's ExecutionComplete may be awaited (Action.visit).
COMPLETION_HANDLERS = "completion_handlers"


# The kind of a handler the engine does not dispatch by itself: its ``matches(event)`` decides
# for each event of the run, as every handler of launch's does (the general path).
MATCHER_KIND = "matcher"


def handler_step(handler: Any, planner: Any, origin: str) -> AddHandler | None:
    """The plan step that registers ``handler``; None for an object that is no event handler
    (no kind mlaunch dispatches, and no ``matches(event)``)."""
    kind = getattr(handler, "kind", "")
    if not kind:
        if not callable(getattr(handler, "matches", None)):
            return None
        kind = MATCHER_KIND
    entities, callback = getattr(handler, "entities", []), getattr(handler, "callback", None)
    matcher = handler.process_matcher() if hasattr(handler, "process_matcher") else None
    if kind == MATCHER_KIND:
        matcher = None  # its matches(event) decides, event by event
        if getattr(type(handler), "handle", EventHandler.handle) is not EventHandler.handle:
            entities, callback = [], handler.handle  # a handler of its own: its handle() says
    return AddHandler(
        origin=origin,
        kind=kind,
        matcher=matcher,
        body=planner.defer(entities, origin, callback=callback),
        io_callbacks=dict(getattr(handler, "io_callbacks", {})),
        once=bool(getattr(handler, "handle_once", False)),
        handler=handler,
    )


def register_step(context: Any, handler: Any, origin: str) -> AddHandler | None:
    """``handler_step`` for a handler registered with ``context``; the run notes from then on
    that actions' completions may be awaited (ExecutionComplete)."""
    step = handler_step(handler, context.planner, origin)
    if step is not None and step.kind in ("execution_complete", MATCHER_KIND):
        context.run_state[COMPLETION_HANDLERS] = True
    return step


# launch's base classes, by the names extensions import.
BaseEventHandler = EventHandler


class _ActionIs:
    """A process matcher: the process of this action (a class, not a lambda: a plan that holds
    it can be stored in the plan cache)."""

    __slots__ = ("target",)

    def __init__(self, target: object) -> None:
        self.target = target

    def __call__(self, spec: Any) -> bool:
        return spec.action is self.target


class _ActionMatches:
    """A process matcher: a process whose action the launch file's predicate accepts."""

    __slots__ = ("predicate",)

    def __init__(self, predicate: Callable[[Any], object]) -> None:
        self.predicate = predicate

    def __call__(self, spec: Any) -> bool:
        return bool(self.predicate(spec.action))
