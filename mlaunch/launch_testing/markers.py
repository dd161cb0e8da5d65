"""``launch_testing.markers``: ``keep_alive`` on ``generate_test_description``, and
``retry_on_failure`` on a test method.

Markers only record what they mean on the decorated object; the loader and runner read it.
"""

from __future__ import annotations

import functools
import time

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable
    from typing import Any


def _markers(function: Any) -> dict[str, Any]:
    if not hasattr(function, "__markers__"):
        function.__markers__ = {}
    markers: dict[str, Any] = function.__markers__
    return markers


def keep_alive(test_description: Any) -> Any:
    """The launch stays up when all its processes have ended, until the active tests finish."""
    _markers(test_description)["keep_alive"] = True
    return test_description


def retry_on_failure(*, times: int, delay: float | None = None) -> Callable[[Any], Any]:
    """Run a test method up to ``times`` times while it fails an assertion."""
    if times <= 0:
        raise ValueError(f"retry_on_failure: times is {times!r}, expected a number >= 1")

    def decorate(method: Any) -> Any:
        @functools.wraps(method)
        def retried(self: Any, *args: Any, **kwargs: Any) -> Any:
            for _ in range(times - 1):
                try:
                    return method(self, *args, **kwargs)
                except AssertionError:
                    if delay:
                        time.sleep(delay)  # the user's own pacing between attempts
            return method(self, *args, **kwargs)

        return retried

    return decorate


__all__ = ["keep_alive", "retry_on_failure"]
