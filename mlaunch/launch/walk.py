"""One walk of a launch description, without resolving anything: every entity in order.

Each entity comes with whether it is ``conditional`` (under a condition, or in a part that runs
only if something happens: a timer's or an event handler's actions) and whether it is
``deferred`` (a timer's or a handler's: visited when it fires, not with the description). What
a static reading needs is served by this one walk: the arguments ``--show-args`` lists
(mlaunch.resolve.resolver.collect_arguments), what a run must attach for bodies that have not
fired yet (the resolver's needs) and what those bodies read (mlaunch.resolve.binding). Resolve
itself visits the description through the seam (``visit(context)``), which evaluates as it goes.

An include is followed only where the caller says how (``include``): a static reading can load
the file an include names when its path resolves without running anything.
"""

from __future__ import annotations

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable, Iterable, Iterator


class Visit:
    """One entity met by the walk."""

    __slots__ = ("conditional", "deferred", "entity")

    def __init__(self, entity: object, conditional: bool, deferred: bool) -> None:
        self.entity = entity
        self.conditional = conditional
        self.deferred = deferred


def children(entity: object) -> list[tuple[object, bool]]:
    """The entities directly inside ``entity``, each with whether it runs later (deferred)."""
    from mlaunch.launch.actions.group_action import GroupAction
    from mlaunch.launch.actions.include_launch_description import IncludeLaunchDescription
    from mlaunch.launch.actions.register_event_handler import RegisterEventHandler
    from mlaunch.launch.actions.timer_action import TimerAction
    from mlaunch.launch.launch_description import LaunchDescription

    if isinstance(entity, LaunchDescription):
        return [(e, False) for e in entity.entities]
    if isinstance(entity, GroupAction):
        return [(e, False) for e in entity.actions]  # as written, without what scopes them
    if isinstance(entity, IncludeLaunchDescription):
        return []  # what it brings in is the caller's to say (``include`` of walk)
    if isinstance(entity, TimerAction):
        return [(e, True) for e in entity.actions]
    if isinstance(entity, RegisterEventHandler):
        handler = entity.event_handler
        return [(e, True) for e in getattr(handler, "entities", None) or ()]
    get = getattr(entity, "get_sub_entities", None)
    return [(e, False) for e in get()] if get is not None else []


def walk(
    roots: Iterable[object],
    *,
    include: Callable[[object, bool], Iterable[object]] | None = None,
) -> Iterator[Visit]:
    """Every entity below ``roots``, depth first in written order, each once.

    ``include(entity, conditional)`` gives what an IncludeLaunchDescription brings in (nothing
    when it is not given, or when it returns nothing).
    """
    from mlaunch.launch.actions.include_launch_description import IncludeLaunchDescription

    stack: list[tuple[object, bool, bool]] = [(r, False, False) for r in reversed(list(roots))]
    seen: set[int] = set()
    while stack:
        entity, conditional, deferred = stack.pop()
        if id(entity) in seen:
            continue  # a handler may list itself among what it registers
        seen.add(id(entity))
        conditional = conditional or getattr(entity, "condition", None) is not None
        yield Visit(entity, conditional, deferred)
        inner = children(entity)
        if include is not None and isinstance(entity, IncludeLaunchDescription):
            inner = [(e, False) for e in include(entity, conditional)]
        for child, later in reversed(inner):
            stack.append((child, conditional or later, deferred or later))
