"""The parts attached to a run, each behind a wall of its own (colcon's EventReactor).

A part (the status view, the control socket, lifecycle driving, the LoadNode driver, the smoke
checks, the exit summary ...) is attached to a run before its loop starts and from then on only
reacts: to the records on the record stream, to timers, to files in the loop's selector. What a
part subscribes, schedules or registers while it is being attached, or while one of its own
callbacks runs, belongs to it (``Reactor.own``). When any of those raises, or its ``close()``
does, the run says so in one line naming the part, detaches it (its subscriptions, timers and
files go, its ``close()`` is called) and goes on. A part the run cannot go on without
(``essential``) ends the run through the stop ladder, with exit status 70: never SIGKILL first.

The supervisor's own machinery (the stop ladder, respawn, TimerActions, the children's pipes)
never goes through ``own``, so a part's callback that starts or stops a process does not make
that process's timers or pipes the part's.
"""

from __future__ import annotations

import selectors

from mlaunch.engine.part import Part
from mlaunch.plan.records import RecordStream

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable, Mapping

    from _typeshed import FileDescriptorLike

    from mlaunch.plan.records import Subscriber


class Attachment:
    """One attached part and what the reactor knows of it."""

    __slots__ = ("detached", "essential", "name", "part")

    def __init__(self, name: str, essential: bool) -> None:
        self.name = name
        self.essential = essential
        self.part: Part | None = None
        self.detached = False


class Owned:
    """A callback of a part: called with its part as the owner, its failure contained.

    Equal to the callback it wraps, so a part unsubscribes the function it subscribed.
    """

    __slots__ = ("attachment", "callback", "reactor")

    def __init__(self, reactor: Reactor, attachment: Attachment, callback: Callable[..., object]):
        self.reactor = reactor
        self.attachment = attachment
        self.callback = callback

    def __call__(self, *args: object) -> None:
        if not self.attachment.detached:
            self.reactor.call(self.attachment, self.callback, *args)

    def __eq__(self, other: object) -> bool:
        if isinstance(other, Owned):
            return other is self or other.callback == self.callback
        return bool(self.callback == other)

    def __hash__(self) -> int:
        return hash(self.callback)

    def __repr__(self) -> str:
        return f"Owned({self.attachment.name}, {self.callback!r})"


class Reactor:
    """The run's attached parts, and the wall around each.

    ``events`` and ``selector``: where a detached part's subscriptions and files are removed
    from. ``on_failure(name, error, essential)``: how the run reports a failed part and decides
    whether it goes on (the supervisor's ``part_failed``).
    """

    def __init__(
        self,
        records: RecordStream,
        selector: selectors.BaseSelector,
        on_failure: Callable[[str, BaseException, bool], None],
    ) -> None:
        self.records = records
        self.selector = selector
        self.on_failure = on_failure
        self.attachments: list[Attachment] = []
        # The part whose attach or callback is running: what is registered now is its own.
        self.current: Attachment | None = None

    def own(self, callback: Callable[..., object]) -> Callable[..., object]:
        """``callback`` as the current part's (contained), or as it is outside any part."""
        if self.current is None or isinstance(callback, Owned):
            return callback
        return Owned(self, self.current, callback)

    def call(
        self, attachment: Attachment, callback: Callable[..., object], *args: object
    ) -> object:
        """``callback(*args)`` as ``attachment``'s: what it registers is the part's, and its
        failure detaches the part (None then)."""
        outer, self.current = self.current, attachment
        try:
            return callback(*args)
        except Exception as e:  # a part's bug or a surprise from its library: never the run's
            self.failed(attachment, e)
            return None
        finally:
            self.current = outer

    def attach(
        self, name: str, make: Callable[[], Part | None], *, essential: bool = False
    ) -> Part | None:
        """Make a part with ``make`` (which subscribes and schedules what it needs); None if
        there is nothing to attach or making it failed (said, and the run goes on)."""
        attachment = Attachment(name, essential)
        self.attachments.append(attachment)
        part = self.call(attachment, make)
        if not isinstance(part, Part) or attachment.detached:
            self.attachments.remove(attachment)
            return None
        attachment.part = part
        return part

    def parts(self) -> list[Part]:
        """The parts still attached, in the order they were attached."""
        return [a.part for a in self.attachments if a.part is not None and not a.detached]

    def failed(self, attachment: Attachment, error: BaseException) -> None:
        """A part raised: detach it, then let the run say it and decide whether it goes on."""
        if attachment.detached:
            return
        self.detach(attachment)
        self.on_failure(attachment.name, error, attachment.essential)

    def detach(self, attachment: Attachment) -> None:
        """Remove what the part holds in the run: subscriptions, files, timers (which no longer
        fire), then call its ``close()``."""
        attachment.detached = True
        mine = [s for s in self.records.subscribers if _owned_by(s, attachment)]
        for subscriber in mine:
            self.records.subscribers.remove(subscriber)
        try:
            keys = list(self.selector.get_map().values())
        except (AttributeError, RuntimeError):  # the loop's selector is closed: the run ended
            keys = []
        for key in keys:
            if _owned_by(key.data, attachment):
                self.selector.unregister(key.fileobj)
        if attachment.part is not None:
            self._close(attachment)

    def close_all(self) -> None:
        """The end of the run: close every part still attached, in the order attached."""
        for attachment in self.attachments:
            if not attachment.detached:
                attachment.detached = True
                self._close(attachment)

    def _close(self, attachment: Attachment) -> None:
        part = attachment.part
        if part is None:
            return
        try:
            part.close()
        except Exception as e:
            self.on_failure(attachment.name, e, False)


class RunRecords(RecordStream):
    """The supervisor's record stream: a subscriber that a part adds is the part's."""

    def __init__(self) -> None:
        super().__init__()
        self.reactor: Reactor | None = None

    def subscribe(self, subscriber: Subscriber) -> None:
        super().subscribe(subscriber if self.reactor is None else self.reactor.own(subscriber))


def _owned_by(callback: object, attachment: Attachment) -> bool:
    return isinstance(callback, Owned) and callback.attachment is attachment


class PartSelector(selectors.BaseSelector):
    """The loop's selector as parts see it: what they register is theirs (``Reactor.own``).

    The loop and the supervisor's own pipes use the selector under it.
    """

    def __init__(self, selector: selectors.BaseSelector, reactor: Reactor) -> None:
        self._selector = selector
        self._reactor = reactor

    def register(
        self, fileobj: FileDescriptorLike, events: int, data: object = None
    ) -> selectors.SelectorKey:
        return self._selector.register(fileobj, events, self._owned(data))

    def unregister(self, fileobj: FileDescriptorLike) -> selectors.SelectorKey:
        return self._selector.unregister(fileobj)

    def modify(
        self, fileobj: FileDescriptorLike, events: int, data: object = None
    ) -> selectors.SelectorKey:
        return self._selector.modify(fileobj, events, self._owned(data))

    def select(self, timeout: float | None = None) -> list[tuple[selectors.SelectorKey, int]]:
        return self._selector.select(timeout)

    def close(self) -> None:
        self._selector.close()

    def get_map(self) -> Mapping[FileDescriptorLike, selectors.SelectorKey]:
        return self._selector.get_map()

    def _owned(self, data: object) -> object:
        return self._reactor.own(data) if callable(data) else data
