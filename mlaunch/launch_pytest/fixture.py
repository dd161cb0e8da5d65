"""``@launch_pytest.fixture``: a pytest fixture whose value is a launch, started by the plugin.

The decorated function returns a LaunchDescription, or a tuple whose first item is one (the
value tests receive is what it returned). The wrapper starts it on a LaunchService in a thread
of its own, waits for its ReadyToTest (one is added at the end when the description has none),
hands the value to the tests, and shuts the launch down at the end of the fixture's scope.
"""

from __future__ import annotations

import functools

import pytest

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable, Iterator
    from typing import Any


def fixture(
    decorated: Callable[..., Any] | None = None,
    *args: Any,
    shutdown_when_idle: bool = True,
    auto_shutdown: bool = True,
    **kwargs: Any,
) -> Any:
    """Declare a launch fixture; ``*args``/``**kwargs`` go to ``pytest.fixture`` (scope, params).

    ``shutdown_when_idle``: the launch ends when nothing runs any more. ``auto_shutdown``: it is
    shut down after the tests that run while it is up; False waits for it to end by itself.
    """

    def decorate(function: Callable[..., Any]) -> Any:
        from mlaunch.launch_pytest.plugin import LaunchRun

        @functools.wraps(function)
        def launch_fixture(*f_args: Any, **f_kwargs: Any) -> Iterator[Any]:
            value = function(*f_args, **f_kwargs)
            run = LaunchRun.start(
                value,
                name=function.__name__,
                shutdown_when_idle=shutdown_when_idle,
                auto_shutdown=auto_shutdown,
            )
            try:
                yield value
            finally:
                run.finish()

        launch_fixture._launch_pytest_fixture = True  # type: ignore[attr-defined]
        return pytest.fixture(*args, **kwargs)(launch_fixture)

    if decorated is None:
        return decorate
    return decorate(decorated)
