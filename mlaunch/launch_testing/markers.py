"""Decorators a launch test file puts on ``generate_test_description`` and its test classes.

They only record what they mean on the decorated object; the loader and runner read it.
"""

from __future__ import annotations

import functools
import inspect
import time
import unittest

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable, Iterable, Iterator
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


def post_shutdown_test() -> Callable[[type], type]:
    """Mark a TestCase class to run after the launch has shut down."""

    def decorate(test_class: type) -> type:
        if not isinstance(test_class, type):
            raise TypeError(
                f"post_shutdown_test() decorates TestCase classes, not {type(test_class).__name__}"
            )
        test_class.__post_shutdown_test__ = True  # type: ignore[attr-defined]
        return test_class

    return decorate


def ready_to_test_action_timeout(timeout: float) -> Callable[[Any], Any]:
    """How long the runner waits for ReadyToTest (15 s by default)."""

    def decorate(function: Any) -> Any:
        function.__ready_to_test_action_timeout__ = timeout
        return function

    return decorate


def parametrize(argnames: str, argvalues: Iterable[Any]) -> Callable[[Any], Any]:
    """Launch the test description once per value, like ``pytest.mark.parametrize``.

    ``argnames`` is comma separated; each value is a tuple (or one value for one name). The
    decorated function yields ``(description function, {name: value})`` pairs.
    """
    names = [name.strip() for name in argnames.split(",") if name.strip()]
    values = [v if isinstance(v, tuple) else (v,) for v in argvalues]

    def decorate(function: Any) -> Any:
        def runs() -> Iterator[tuple[Any, dict[str, Any]]]:
            for value in values:
                if len(value) != len(names):
                    raise ValueError(
                        f"parametrize({argnames!r}): value {value!r} has {len(value)} items,"
                        f" expected {len(names)}"
                    )
                bound = dict(zip(names, value, strict=True))
                partial = functools.partial(function, **bound)
                functools.update_wrapper(partial, function)
                yield partial, bound

        runs.__parametrized__ = True  # type: ignore[attr-defined]
        runs.__wrapped_description__ = function  # type: ignore[attr-defined]
        if hasattr(function, "__ready_to_test_action_timeout__"):
            runs.__ready_to_test_action_timeout__ = function.__ready_to_test_action_timeout__  # type: ignore[attr-defined]
        if hasattr(function, "__markers__"):
            runs.__markers__ = function.__markers__  # type: ignore[attr-defined]
        return runs

    return decorate


def is_test_case_class(value: Any) -> bool:
    return inspect.isclass(value) and issubclass(value, unittest.TestCase)
