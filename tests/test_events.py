"""The engine's record stream: records handled in order, one at a time, after a description's visit.

Pure tests of RecordStream, then supervisor runs of real short-lived children whose order of
records and lines is compared with what launch does (and, where the reference ros2 launch is
built on this machine, with its own output).
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
import reference
from test_supervision import Harness, plan_from

from mlaunch.plan.records import (
    Exited,
    HandedOff,
    Output,
    Record,
    RecordStream,
    Said,
    ShutdownBegun,
    Started,
    StoppingAll,
)
from mlaunch.plan.steps import Need, Plan, Step

PY = sys.executable


def test_records_emitted_while_one_is_handled_wait_for_it_to_finish() -> None:
    stream = RecordStream()
    seen: list[str] = []

    def first(record: Record) -> None:
        seen.append(f"first {record!r}")
        if isinstance(record, Said) and record.text == "a":
            stream.emit(Said("INFO", "t", "b"))  # queued: "a" reaches `second` before "b"

    stream.subscribe(first)
    stream.subscribe(lambda event: seen.append(f"second {event!r}"))
    stream.emit(Said("INFO", "t", "a"))
    assert [s.split("text=")[1] for s in seen] == ["'a')", "'a')", "'b')", "'b')"]
    assert [s.split()[0] for s in seen] == ["first", "second", "first", "second"]
    assert stream.pending == 0


def test_a_held_stream_queues_until_released_but_say_now_is_said_at_once() -> None:
    stream = RecordStream()
    seen: list[str] = []
    stream.subscribe(lambda event: seen.append(getattr(event, "text", type(event).__name__)))
    stream.hold()
    stream.emit(Said("INFO", "t", "queued"))
    stream.hold()  # holds nest: a handler's body visited inside a description's visit
    stream.say_now(Said("INFO", "t", "now"))
    stream.release()
    assert seen == ["now"] and stream.pending == 1
    stream.release()
    assert seen == ["now", "queued"] and stream.pending == 0


def test_a_subscriber_that_raises_leaves_the_stream_usable() -> None:
    stream = RecordStream()
    seen: list[Record] = []

    def fails(record: Record) -> None:
        if isinstance(record, StoppingAll):
            raise RuntimeError("boom")

    stream.subscribe(fails)
    stream.subscribe(seen.append)
    with pytest.raises(RuntimeError, match="boom"):
        stream.emit(StoppingAll())
    stream.emit(ShutdownBegun("after"))
    assert [type(e) for e in seen] == [ShutdownBegun]


def test_a_handoff_is_emitted_and_said_when_nothing_takes_it() -> None:
    """A Handoff (a container's component loads) goes to the part that carries it out; with
    no such part attached it is said as an error, never dropped in silence."""
    from mlaunch.launch_ros.composition import LoadComponents

    step = LoadComponents(origin="c.launch.py:1", target="/container")
    h = Harness(Plan(steps=[step]))
    handed: list[HandedOff] = []
    h.sup.records.subscribe(lambda e: handed.append(e) if isinstance(e, HandedOff) else None)
    assert h.run() == 0
    assert [e.step for e in handed] == [step]
    assert (
        b"LoadComponents (c.launch.py:1): nothing in this run carries it out (it needs"
        b" components); not done"
    ) in bytes(h.screen)


def test_the_supervisor_refuses_a_step_kind_it_does_not_know() -> None:
    class Mystery(Step):
        __slots__ = ()

    h = Harness(Plan(steps=[Mystery(origin="x.launch.py:3")]))
    with pytest.raises(TypeError, match=r"Mystery step \(x.launch.py:3\)"):
        h.sup.run()


LATE_HANDLERS = """
    import sys
    from launch import LaunchDescription
    from launch.actions import ExecuteProcess, LogInfo, RegisterEventHandler
    from launch.event_handlers import OnProcessExit, OnProcessStart


    def generate_launch_description():
        p = ExecuteProcess(
            cmd=[sys.executable, '-c', 'print("hello")'], name='p', output='screen')
        return LaunchDescription([
            p,
            LogInfo(msg='visited'),
            RegisterEventHandler(
                OnProcessStart(target_action=p, on_start=[LogInfo(msg='saw start')])),
            RegisterEventHandler(
                OnProcessExit(target_action=p, on_exit=[LogInfo(msg='saw exit')])),
        ])
"""
# What ros2 launch prints for LATE_HANDLERS (launch 3.4.3), pids and paths aside.
LATE_EXPECTED = [
    "[INFO] [launch.user]: visited",
    "[INFO] [p-1]: process started with pid [PID]",
    "[INFO] [launch.user]: saw start",
    "[p-1] hello",
    "[INFO] [p-1]: process has finished cleanly [pid PID]",
    "[INFO] [launch.user]: saw exit",
]


def _lines(text: str) -> list[str]:
    """Lines of a launch's output without timestamps, pids and launch's own preamble."""
    out = []
    for line in text.splitlines():
        line = re.sub(r"^\[\d+\.\d+\] ", "", line)
        line = re.sub(r"pid \[\d+\]", "pid [PID]", line)
        line = re.sub(r"pid \d+", "pid PID", line)
        if "[launch]:" not in line:
            out.append(line)
    return out


def test_a_handler_registered_after_its_target_sees_the_start(tmp_path: Path) -> None:
    """launch starts processes after visiting the whole description (issue 12, item 1)."""
    path = tmp_path / "late.launch.py"
    path.write_text(textwrap.dedent(LATE_HANDLERS))
    h = Harness(plan_from(path, tmp_path))
    records: list[str] = []
    h.sup.records.subscribe(
        lambda e: (
            records.append(type(e).__name__) if isinstance(e, (Started, Output, Exited)) else None
        )
    )
    assert h.run() == 0
    assert _lines(h.text) == LATE_EXPECTED
    assert records == ["Started", "Output", "Exited"]


@pytest.mark.skipif(not reference.ENV_SH.exists(), reason=reference.MISSING)
def test_late_handlers_print_what_the_reference_ros2_launch_prints(tmp_path: Path) -> None:
    path = tmp_path / "late.launch.py"
    path.write_text(textwrap.dedent(LATE_HANDLERS))
    env = {k: v for k, v in os.environ.items() if not k.startswith("MLAUNCH")}
    env["ROS_LOG_DIR"] = str(tmp_path / "logs")
    done = subprocess.run(
        ["bash", "-c", f"source {reference.ENV_SH} && ros2 launch {path}"],
        capture_output=True,
        text=True,
        env=env,
        timeout=60,
    )
    assert done.returncode == 0, done.stderr
    assert _lines(done.stdout + done.stderr) == LATE_EXPECTED


# --- what attaches to a run ------------------------------------------------------------------


def test_resolve_notes_lifecycle_needs_in_deferred_bodies_and_events() -> None:
    from mlaunch.launch.actions import EmitEvent, ExecuteProcess, RegisterEventHandler, TimerAction
    from mlaunch.launch.event_handlers import OnProcessExit
    from mlaunch.launch_ros.events import ChangeState
    from mlaunch.resolve.resolver import resolve

    def needs(*entities: object) -> set[Need]:
        from mlaunch.launch.actions import LaunchDescription

        return resolve(LaunchDescription(list(entities)), path=None, arguments={}, environ={}).needs

    p = ExecuteProcess(cmd=["true"])
    change = EmitEvent(event=ChangeState(lifecycle_node_matcher=lambda _: True, transition_id=1))
    assert needs(p, TimerAction(period=1.0, actions=[])) == set()
    assert needs(change) == {Need.LIFECYCLE}
    handler = RegisterEventHandler(OnProcessExit(target_action=p, on_exit=[change]))
    assert needs(p, handler) == {Need.LIFECYCLE}  # deep in a handler that has not fired


def test_a_lifecycle_need_seen_only_at_run_time_attaches_lifecycle_driving() -> None:
    """A ChangeState from a handler written as a function: no need was visible before the run."""
    from mlaunch.app import parts
    from mlaunch.app.options import Options
    from mlaunch.launch_ros.events import ChangeState
    from mlaunch.parts.lifecycle import LifecycleManager
    from mlaunch.plan.records import LaunchEvent

    h = Harness(Plan())
    run = parts.Run(Options("x.launch.py"), h.sup.plan, h.sup, h.printer)
    watch = parts.lifecycle(run)
    assert run.lifecycle is None
    event = ChangeState(lifecycle_node_matcher=lambda _: True, transition_id=3)
    h.sup.records.emit(LaunchEvent(event))
    try:
        assert isinstance(run.lifecycle, LifecycleManager)
        assert "has no handler" not in h.text
        assert "matched no running lifecycle node" in h.text  # the manager took it
    finally:
        watch.close()
