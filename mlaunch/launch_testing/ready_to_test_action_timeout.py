"""``launch_testing.ready_to_test_action_timeout``: how long the runner waits for ReadyToTest."""

from __future__ import annotations

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable
    from typing import Any


def ready_to_test_action_timeout(timeout: float) -> Callable[[Any], Any]:
    """How long the runner waits for ReadyToTest (15 s by default)."""

    def decorate(function: Any) -> Any:
        function.__ready_to_test_action_timeout__ = timeout
        return function

    return decorate


__all__ = ["ready_to_test_action_timeout"]
