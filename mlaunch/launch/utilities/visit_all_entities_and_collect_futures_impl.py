"""``visit_all_entities_and_collect_futures``: visit an entity tree depth-first, keep futures."""

from __future__ import annotations

from typing import Any


def visit_all_entities_and_collect_futures(entity: Any, context: Any) -> list[tuple[Any, Any]]:
    """Visit ``entity`` and, depth-first, what each visit returns; (entity, future) pairs of the
    entities whose ``get_asyncio_future()`` gave one, in visiting order."""
    more = entity.visit(context)
    collected: list[tuple[Any, Any]] = []
    future = entity.get_asyncio_future()
    if future is not None:
        collected.append((entity, future))
    for sub_entity in more or ():
        collected.extend(visit_all_entities_and_collect_futures(sub_entity, context))
    return collected
