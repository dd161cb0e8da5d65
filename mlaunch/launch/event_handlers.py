"""Event handlers: what to resolve when a process starts, exits, prints, or the launch shuts down.

Handlers are data. RegisterEventHandler turns one into an AddHandler step of the plan; the
supervisor fires it and resolves its entities with the context captured at registration.
"""

from __future__ import annotations

from collections.abc import Iterable

from mlaunch.plan.origin import caller_origin

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable
    from typing import Any


def _as_entities(value: Any) -> tuple[list[Any], Callable[..., Any] | None]:
    """Split ``on_*`` into entities or a callable(event, context) -> entities."""
    if value is None:
        return [], None
    if callable(value) and not hasattr(value, "visit"):
        return [], value
    if isinstance(value, Iterable) and not isinstance(value, (str, bytes)):
        return list(value), None
    return [value], None


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
        if callable(target) and not hasattr(target, "visit"):
            return lambda spec: bool(target(spec.action))
        return lambda spec: spec.action is target

    def describe_short(self) -> str:
        return type(self).__name__


class OnProcessStart(EventHandler):
    kind = "process_start"

    def __init__(self, *, target_action: Any = None, on_start: Any, handle_once: bool = False):
        super().__init__(target_action=target_action, entities=on_start, handle_once=handle_once)


class OnProcessExit(EventHandler):
    kind = "process_exit"

    def __init__(self, *, target_action: Any = None, on_exit: Any, handle_once: bool = False):
        super().__init__(target_action=target_action, entities=on_exit, handle_once=handle_once)


class OnProcessIO(EventHandler):
    """Callables receive the ProcessIO event (bytes in ``event.text``), as in ROS 2."""

    kind = "process_io"

    def __init__(
        self,
        *,
        target_action: Any = None,
        on_stdin: Callable[[Any], Any] | None = None,
        on_stdout: Callable[[Any], Any] | None = None,
        on_stderr: Callable[[Any], Any] | None = None,
        handle_once: bool = False,
    ) -> None:
        super().__init__(target_action=target_action, handle_once=handle_once)
        self.io_callbacks = {
            k: v for k, v in (("stdout", on_stdout), ("stderr", on_stderr)) if v is not None
        }


class OnShutdown(EventHandler):
    kind = "shutdown"

    def __init__(self, *, on_shutdown: Any, handle_once: bool = False) -> None:
        super().__init__(entities=on_shutdown, handle_once=handle_once)


class OnExecutionComplete(EventHandler):
    """Fires when the target action completes: a process when it exits for good, a timer when
    it has fired; only for targets visited after the handler was registered (as in launch)."""

    kind = "execution_complete"

    def __init__(
        self, *, target_action: Any = None, on_completion: Any, handle_once: bool = False
    ) -> None:
        super().__init__(
            target_action=target_action, entities=on_completion, handle_once=handle_once
        )


__all__ = [
    "EventHandler",
    "OnExecutionComplete",
    "OnProcessExit",
    "OnProcessIO",
    "OnProcessStart",
    "OnShutdown",
    "returned_entities",
]
