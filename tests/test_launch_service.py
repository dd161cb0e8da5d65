"""launch.LaunchService on mlaunch's engine: include, run, shutdown from another thread,
include while running, return codes, process_details."""

from __future__ import annotations

import sys
import threading

from mlaunch.app.launch_service import LaunchService
from mlaunch.launch.actions import (
    ExecuteProcess,
    LaunchDescription,
    OpaqueFunction,
    RegisterEventHandler,
)
from mlaunch.launch.event_handlers import OnProcessIO, OnProcessStart

DEADLINE = 30.0


class Screen:
    """Collects what the service prints, and lets a test wait for a text."""

    def __init__(self) -> None:
        self.data = b""
        self.changed = threading.Condition()

    def __call__(self, data: bytes) -> None:
        with self.changed:
            self.data += data
            self.changed.notify_all()

    def wait_for(self, text: str, timeout: float = DEADLINE) -> bool:
        with self.changed:
            return self.changed.wait_for(lambda: text.encode() in self.data, timeout)


def python(code: str, **kwargs: object) -> ExecuteProcess:
    return ExecuteProcess(cmd=[sys.executable, "-c", code], output="screen", **kwargs)  # type: ignore[arg-type]


SLEEPER = "import time\nprint('up', flush=True)\ntime.sleep(60)"


def in_thread(function: object) -> threading.Thread:
    thread = threading.Thread(target=function, daemon=True)  # type: ignore[arg-type]
    thread.start()
    return thread


def test_runs_what_was_included_and_ends_when_idle() -> None:
    screen = Screen()
    service = LaunchService(screen=screen)
    service.include_launch_description(LaunchDescription([python("print('first')")]))
    service.include_launch_description(LaunchDescription([python("print('second')")]))
    assert service.run() == 0
    assert b"first" in screen.data and b"second" in screen.data


def test_shutdown_and_include_from_another_thread() -> None:
    screen = Screen()
    service = LaunchService(screen=screen)
    service.include_launch_description(LaunchDescription([python(SLEEPER, name="sleeper")]))

    def drive() -> None:
        assert screen.wait_for("up")
        service.include_launch_description(LaunchDescription([python("print('late')")]))
        assert screen.wait_for("late")
        service.shutdown()

    thread = in_thread(drive)
    assert service.run() == 0
    thread.join(DEADLINE)
    assert b"shutting down: LaunchService.shutdown() called" in screen.data
    assert b"process stopped by SIGINT" in screen.data


def test_the_context_says_is_shutdown_once_asked_and_after_the_run() -> None:
    screen = Screen()
    service = LaunchService(screen=screen)
    service.shutdown()  # not running: nothing to shut down, as launch's
    assert not service.context.is_shutdown
    service.include_launch_description(LaunchDescription([python(SLEEPER, name="sleeper")]))
    seen: list[bool] = []

    def drive() -> None:
        assert screen.wait_for("up")
        seen.append(service.context.is_shutdown)
        service.shutdown()
        seen.append(service.context.is_shutdown)  # at once, in the caller's thread

    thread = in_thread(drive)
    assert service.run() == 0
    thread.join(DEADLINE)
    assert seen == [False, True]

    idle = LaunchService(screen=Screen())
    idle.include_launch_description(LaunchDescription([python("print('done')")]))
    assert idle.run() == 0
    assert idle.context.is_shutdown  # a launch that ended when idle has shut down too


def test_keeps_running_when_idle_until_shutdown() -> None:
    screen = Screen()
    service = LaunchService(screen=screen)
    service.include_launch_description(LaunchDescription([python("print('done')")]))

    def stop_when_done() -> None:
        if screen.wait_for("finished cleanly"):
            service.shutdown()

    in_thread(stop_when_done)
    assert service.run(shutdown_when_idle=False) == 0
    assert b"finished cleanly" in screen.data


def test_launch_arguments_from_argv_and_context() -> None:
    screen = Screen()
    service = LaunchService(argv=["word:=bird"], screen=screen)
    seen: list[str] = []

    def look(context: object) -> None:
        seen.append(context.launch_configurations["word"])  # type: ignore[attr-defined]

    service.include_launch_description(LaunchDescription([OpaqueFunction(function=look)]))
    assert service.context.launch_configurations["word"] == "bird"
    assert service.run() == 0
    assert seen == ["bird"]


def test_handlers_and_process_details() -> None:
    screen = Screen()
    service = LaunchService(screen=screen)
    action = python("print('hi')", name="greeter")
    started: list[object] = []
    lines: list[bytes] = []
    service.include_launch_description(
        LaunchDescription(
            [
                RegisterEventHandler(OnProcessStart(on_start=lambda e, c: started.append(e))),
                RegisterEventHandler(OnProcessIO(on_stdout=lambda e: lines.append(e.text))),
                action,
            ]
        )
    )
    assert action.process_details is None
    assert service.run() == 0
    assert [e.process_name for e in started] == ["greeter-1"]  # type: ignore[attr-defined]
    assert b"".join(lines) == b"hi\n"
    assert action.process_details is not None
    assert action.process_details["name"] == "greeter-1"
    assert action.process_details["cmd"][0] == sys.executable


def test_return_code_of_a_failed_required_process_and_of_a_bad_description() -> None:
    service = LaunchService(screen=Screen())
    service.include_launch_description(
        LaunchDescription([python("raise SystemExit(3)", required=True)])
    )
    assert service.run() == 1
    bad = LaunchService(screen=Screen())
    bad.include_launch_description(
        LaunchDescription([ExecuteProcess(cmd=["/no/such/program-mlaunch"])])
    )
    assert bad.run() == 1


def test_run_only_on_the_main_thread_and_once_at_a_time() -> None:
    service = LaunchService(screen=Screen())
    errors: list[BaseException] = []

    def run() -> None:
        try:
            service.run()
        except RuntimeError as e:
            errors.append(e)

    in_thread(run).join(DEADLINE)
    assert errors and "main thread" in str(errors[0])
    service.shutdown()  # not running: nothing to do, and no error


def test_events_emitted_before_run_wait_for_it() -> None:
    from mlaunch.launch.events import IncludeLaunchDescription

    screen = Screen()
    service = LaunchService(screen=screen)
    service.emit_event(IncludeLaunchDescription(LaunchDescription([python("print('queued')")])))
    assert service.run() == 0
    assert b"queued" in screen.data


def test_importable_as_launch_launch_service() -> None:
    import importlib

    from mlaunch import compat

    compat.install()
    module = importlib.import_module("launch")
    assert module.LaunchService is LaunchService
    assert importlib.import_module("launch.launch_service").LaunchService is LaunchService


def test_run_async_leaves_the_event_loop_free() -> None:
    import asyncio

    screen = Screen()
    service = LaunchService(screen=screen)
    service.include_launch_description(LaunchDescription([python(SLEEPER)]))

    async def main() -> tuple[int, bool]:
        task = asyncio.ensure_future(service.run_async())
        # This coroutine runs while the launch does: the loop is not blocked.
        seen = await asyncio.to_thread(screen.wait_for, "up")
        assert service.event_loop is asyncio.get_running_loop()
        # On the loop's thread shutdown() gives a coroutine to await, as ROS 2's does.
        requested = service.shutdown()
        assert requested is not None
        await requested
        return await asyncio.wait_for(task, DEADLINE), seen

    code, seen = asyncio.run(main())
    assert (code, seen) == (0, True)
    assert service.event_loop is None
    assert b"process stopped by SIGINT" in screen.data


def test_run_in_thread_notices_exits_without_signals() -> None:
    screen = Screen()
    service = LaunchService(screen=screen)
    one_shot = python("print('once')", name="once")
    service.include_launch_description(LaunchDescription([one_shot]))
    thread = service.run_in_thread(shutdown_when_idle=False)
    assert screen.wait_for("process has finished cleanly")
    assert one_shot.return_code == 0
    assert service._is_idle()
    service.shutdown()
    thread.join(DEADLINE)
    assert not thread.is_alive()
    assert service.return_code == 0
