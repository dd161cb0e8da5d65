"""``launch_pytest.tools.process``: wait on a process of the launch fixture from a test, by its
action: its start, its exit, its stdout or stderr.

``*_sync`` functions block the test; the others are coroutines for async tests. ``wait_for_*``
return whether the condition held in time; ``assert_*`` raise the validator's last assertion.
"""

from __future__ import annotations

import asyncio

from mlaunch.launch.events.process.process_exited import ProcessExited

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable
    from typing import Any


def _run(launch_context: Any) -> Any:
    from mlaunch.launch_pytest.plugin import recorders

    return recorders.of(launch_context)


def _text(run: Any, action: Any, fd: int) -> str:
    if not getattr(action, "cached_output", False):
        # As ROS 2: the output is kept only for processes created with cached_output=True.
        raise RuntimeError(
            "cached output must be true to be able to get the output of a process"
            " (ExecuteProcess(..., cached_output=True))"
        )
    try:
        events = run.proc_output._io_handler[action]
    except (KeyError, TypeError):
        return ""  # not started yet, or nothing printed
    return "".join(e.text.decode("utf-8", "replace") for e in events if e.fd == fd)


def _wait_output(
    launch_context: Any,
    action: Any,
    holds: Callable[[str], bool],
    timeout: float | None,
    fd: int,
) -> bool:
    """Wait until ``holds(output so far)``; the output is checked at once, then on each line."""
    run = _run(launch_context)
    with run.proc_output.io_event:
        return bool(
            run.proc_output.io_event.wait_for(lambda: holds(_text(run, action, fd)), timeout)
        )


def _passes(validate: Callable[[str], Any]) -> Callable[[str], bool]:
    """For assert_*: the validator passes when it raises no AssertionError (its value is
    ignored, as in ROS 2)."""

    def holds(output: str) -> bool:
        try:
            validate(output)
        except AssertionError:
            return False
        return True

    return holds


def _assert_output(
    launch_context: Any,
    action: Any,
    validate: Callable[[str], Any],
    timeout: float | None,
    fd: int,
) -> None:
    if not _wait_output(launch_context, action, _passes(validate), timeout, fd):
        validate(_text(_run(launch_context), action, fd))  # raises its own assertion


def _output_waiter(fd: int) -> Callable[..., bool]:
    def wait(
        launch_context: Any,
        action: Any,
        validate_output: Callable[[str], Any],
        timeout: float | None = None,
    ) -> bool:
        """Whether ``validate_output(output so far)`` became true within ``timeout`` seconds."""
        return _wait_output(
            launch_context, action, lambda out: bool(validate_output(out)), timeout, fd
        )

    return wait


def _output_asserter(fd: int) -> Callable[..., None]:
    def check(
        launch_context: Any,
        action: Any,
        validate_output: Callable[[str], Any],
        timeout: float | None = None,
    ) -> None:
        """Wait until ``validate_output(output so far)`` raises no AssertionError; else raise."""
        _assert_output(launch_context, action, validate_output, timeout, fd)

    return check


wait_for_output_sync = _output_waiter(1)
wait_for_stderr_sync = _output_waiter(2)
assert_output_sync = _output_asserter(1)
assert_stderr_sync = _output_asserter(2)


def _wait_event(launch_context: Any, action: Any, exited: bool, timeout: float | None) -> bool:
    run = _run(launch_context)
    info = run.proc_info

    def seen() -> bool:
        event = info._proc_info_handler._info.get(action)
        return event is not None and (not exited or isinstance(event, ProcessExited))

    with info.proc_event:
        return bool(info.proc_event.wait_for(seen, timeout))


def wait_for_start_sync(launch_context: Any, action: Any, timeout: float | None = None) -> bool:
    return _wait_event(launch_context, action, False, timeout)


def wait_for_exit_sync(launch_context: Any, action: Any, timeout: float | None = None) -> bool:
    return _wait_event(launch_context, action, True, timeout)


def _in_a_thread(function: Callable[..., Any]) -> Callable[..., Any]:
    """The coroutine version of a ``*_sync`` function: it waits in a worker thread."""

    async def run(*args: Any, **kwargs: Any) -> Any:
        return await asyncio.to_thread(function, *args, **kwargs)

    run.__name__ = run.__qualname__ = function.__name__.removesuffix("_sync")
    return run


wait_for_output = _in_a_thread(wait_for_output_sync)
assert_output = _in_a_thread(assert_output_sync)
wait_for_stderr = _in_a_thread(wait_for_stderr_sync)
assert_stderr = _in_a_thread(assert_stderr_sync)
wait_for_start = _in_a_thread(wait_for_start_sync)
wait_for_exit = _in_a_thread(wait_for_exit_sync)

__all__ = [
    "assert_output",
    "assert_output_sync",
    "assert_stderr",
    "assert_stderr_sync",
    "wait_for_exit",
    "wait_for_exit_sync",
    "wait_for_output",
    "wait_for_output_sync",
    "wait_for_start",
    "wait_for_start_sync",
    "wait_for_stderr",
    "wait_for_stderr_sync",
]
