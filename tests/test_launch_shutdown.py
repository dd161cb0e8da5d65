"""Shutting down as launch does.

A launch file's Shutdown(due_to_sigint=True): interactive, the terminal is taken to have sent
SIGINT already, so the processes get SIGTERM after sigterm_timeout; noninteractive (-n), they get
SIGINT. A child that reads its stdin waits meanwhile, as under launch (its stdin is a pipe nobody
writes to, not /dev/null). Handlers that run once the shutdown began see ``is_shutdown``; a
Shutdown while the launch already stops reaches the OnShutdown handlers too.
"""

from __future__ import annotations

import signal
import sys
from typing import Any

import pytest

from mlaunch.app.launch_service import LaunchService
from mlaunch.launch.actions import (
    EmitEvent,
    ExecuteProcess,
    LaunchDescription,
    RegisterEventHandler,
    TimerAction,
)
from mlaunch.launch.actions import Shutdown as ShutdownAction
from mlaunch.launch.event_handlers import OnProcessExit, OnProcessIO, OnShutdown
from mlaunch.launch.events import Shutdown


def _exit_codes(*, noninteractive: bool, due_to_sigint: bool = True) -> tuple[list[int], bytes]:
    codes: list[int] = []
    printed: list[bytes] = []
    reader = ExecuteProcess(
        cmd=[sys.executable, "-S", "-c", "print('ready', flush=True); input()"],
        sigterm_timeout="0.5",
        on_exit=lambda event, context: codes.append(event.returncode),
    )
    shutdown = Shutdown(reason="as if Ctrl-C", due_to_sigint=due_to_sigint)
    # Once the reader says it is up (a SIGINT in its interpreter's start-up would exit 1).
    on_ready = OnProcessIO(
        target_action=reader, on_stdout=lambda event: [EmitEvent(event=shutdown)]
    )
    service = LaunchService(noninteractive=noninteractive, screen=printed.append)
    service.include_launch_description(LaunchDescription([reader, RegisterEventHandler(on_ready)]))
    assert service.run() == 0
    return codes, b"".join(printed)


def test_interactive_the_reader_gets_sigterm_after_its_timeout_and_no_sigint() -> None:
    codes, printed = _exit_codes(noninteractive=False)
    assert codes == [-signal.SIGTERM]
    assert b"0.5 s after the shutdown began, escalating to SIGTERM" in printed


@pytest.mark.parametrize(
    ("noninteractive", "due_to_sigint"), [(True, True), (False, False)], ids=["-n", "plain"]
)
def test_noninteractive_or_a_plain_shutdown_sends_sigint(
    noninteractive: bool, due_to_sigint: bool
) -> None:
    codes, _ = _exit_codes(noninteractive=noninteractive, due_to_sigint=due_to_sigint)
    assert codes == [-signal.SIGINT]


SLEEPER = [sys.executable, "-c", "import time; time.sleep(30)"]
# A sleeper that says when its interpreter is up: a signal sent before that can reach Python
# while it starts (a KeyboardInterrupt in its start-up exits 1, not -2), so a test that
# signals it waits for the line, not for the process to start (it raced on a loaded machine).
READY_SLEEPER = [sys.executable, "-c", "import time; print('ready', flush=True); time.sleep(30)"]


def test_handlers_see_is_shutdown_once_the_run_shuts_down() -> None:
    seen: list[tuple[str, bool]] = []
    quick = ExecuteProcess(cmd=[sys.executable, "-c", "pass"])
    sleeper = ExecuteProcess(cmd=SLEEPER)

    def quick_exited(event: object, context: object) -> list[object]:
        seen.append(("quick", context.is_shutdown))  # type: ignore[attr-defined]
        return [EmitEvent(event=Shutdown(reason="quick is done"))]

    def sleeper_exited(event: object, context: object) -> None:
        seen.append(("sleeper", context.is_shutdown))  # type: ignore[attr-defined]

    service = LaunchService(screen=lambda data: None)
    service.include_launch_description(
        LaunchDescription(
            [
                sleeper,
                RegisterEventHandler(OnProcessExit(target_action=sleeper, on_exit=sleeper_exited)),
                RegisterEventHandler(OnProcessExit(target_action=quick, on_exit=quick_exited)),
                quick,
            ]
        )
    )
    assert service.run() == 0
    assert seen == [("quick", False), ("sleeper", True)]


def test_a_legacy_fixture_stopped_by_the_shutdown_is_no_failure() -> None:
    from mlaunch.launch_testing.legacy import LaunchTestService

    description = LaunchDescription()
    tests = LaunchTestService()
    tests.add_fixture_action(description, ExecuteProcess(cmd=SLEEPER))
    tests.add_test_action(description, ExecuteProcess(cmd=[sys.executable, "-c", "pass"]))
    service = LaunchService(screen=lambda data: None)
    service.include_launch_description(description)
    assert tests.run(service) == 0  # the fixture ends by SIGINT, as the shutdown stops it


def test_a_shutdown_while_shutting_down_reaches_the_on_shutdown_handlers() -> None:
    reasons: list[str] = []
    printed: list[bytes] = []
    service = LaunchService(screen=printed.append)
    service.include_launch_description(
        LaunchDescription(
            [
                ExecuteProcess(cmd=SLEEPER),
                RegisterEventHandler(
                    OnShutdown(on_shutdown=lambda event, context: reasons.append(event.reason))
                ),
                TimerAction(period=0.1, actions=[ShutdownAction(reason="fast")]),
                TimerAction(
                    period=0.5, actions=[ShutdownAction(reason="slow")], cancel_on_shutdown=False
                ),
            ]
        )
    )
    assert service.run() == 0
    assert reasons == ["fast", "slow"]
    assert b"".join(printed).count(b"shutting down") == 1  # the launch stops once


def test_a_launch_files_process_matcher_is_given_the_action() -> None:
    from mlaunch.launch.events import SignalProcess

    codes: list[tuple[str, int]] = []

    def sleeper(name: str) -> ExecuteProcess:
        return ExecuteProcess(
            cmd=READY_SLEEPER,
            on_exit=lambda event, context: codes.append((name, event.returncode)),
        )

    target, other = sleeper("target"), sleeper("other")
    signal_target = SignalProcess(
        signal_number=signal.SIGTERM, process_matcher=lambda action: action is target
    )
    ready: list[object] = []

    def both_ready(event: Any) -> list[EmitEvent]:
        ready.append(event.action)
        return [EmitEvent(event=signal_target)] if len(ready) == 2 else []

    service = LaunchService(screen=lambda data: None)
    service.include_launch_description(
        LaunchDescription(
            [
                target,
                other,
                RegisterEventHandler(
                    OnProcessExit(target_action=target, on_exit=[ShutdownAction()])
                ),
                RegisterEventHandler(OnProcessIO(on_stdout=both_ready)),
            ]
        )
    )
    assert service.run() == 0
    assert codes == [("target", -signal.SIGTERM), ("other", -signal.SIGINT)]
