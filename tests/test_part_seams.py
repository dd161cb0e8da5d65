"""A part is read and tested without the Supervisor: runtime control against a small fake run
that has only what ``ControlledRun`` names, with no process started and no loop turning."""

from __future__ import annotations

import selectors
from collections.abc import Callable, Iterator, Mapping
from typing import TYPE_CHECKING

import pytest

from mlaunch.engine.process import Process
from mlaunch.engine.process_state import RUNNING, STOPPED, ProcessState
from mlaunch.parts.control import AmbiguousLabel, Control, ControlError, ProcessInfo
from mlaunch.plan.records import Controlled, Exited, Record, RecordStream
from mlaunch.plan.steps import ProcessSpec

if TYPE_CHECKING:
    from mlaunch.engine.timers import Timer


class FakeRun:
    """The members of ``ControlledRun``, and nothing else of a Supervisor."""

    def __init__(self, selector: selectors.BaseSelector) -> None:
        self.records = RecordStream()
        self.selector = selector
        self.clock: Callable[[], float] = lambda: 100.0
        self.states: dict[str, ProcessState] = {}
        self.processes: list[Process] = []
        self.shutting_down = False
        self.stopped: list[Process] = []
        self.started: list[Process] = []
        self.cancelled: list[tuple[str, str]] = []

    @property
    def process_states(self) -> Mapping[str, ProcessState]:
        return self.states

    def schedule(
        self,
        delay: float,
        callback: Callable[[], object],
        *,
        keeps_alive: bool = True,
        cancel_on_shutdown: bool = True,
    ) -> Timer:
        raise AssertionError("runtime control schedules nothing of its own")

    def stop(self, process: Process) -> None:
        self.stopped.append(process)

    def start_again(self, old: Process) -> object:
        self.started.append(old)
        return None

    def cancel_respawn(self, label: str, outcome: str) -> None:
        self.cancelled.append((label, outcome))

    def running(self, label: str, pid: int) -> Process:
        spec = ProcessSpec(label=label, argv=("x",), env={}, env_changes={})
        process = Process(spec, len(self.processes))
        process.pid = pid
        self.processes.append(process)
        self.states[label] = ProcessState(label, spec, state=RUNNING, pid=pid, started_at=90.0)
        return process


class FakePrinter:
    """The members of ``Muting``: what runtime control asks of the printer."""

    def __init__(self) -> None:
        self.muted: set[str] = set()

    def is_muted(self, label: str) -> bool:
        return label in self.muted

    def mute(self, label: str, muted: bool = True) -> None:
        (self.muted.add if muted else self.muted.discard)(label)

    def log_tail(self, label: str, count: int) -> list[bytes] | None:
        return None  # a run without log files


@pytest.fixture
def run() -> Iterator[FakeRun]:
    with selectors.DefaultSelector() as selector:
        yield FakeRun(selector)


def control_of(run: FakeRun) -> tuple[Control, list[Record]]:
    seen: list[Record] = []
    run.records.subscribe(seen.append)
    return Control(run, FakePrinter()), seen


def test_a_stop_asks_the_run_and_calls_back_at_the_exit(run: FakeRun) -> None:
    talker = run.running("talker-1", 4242)
    control, seen = control_of(run)
    done: list[ProcessInfo] = []

    control.stop("talker", by="ctl", done=done.append)

    assert run.stopped == [talker] and talker.user_stop == "stop"
    (said,) = [r for r in seen if isinstance(r, Controlled)]
    assert (said.label, said.action, said.by) == ("talker-1", "stop", "ctl")
    assert done == []
    talker.returncode = 0
    run.states["talker-1"].state = STOPPED
    run.records.emit(Exited(talker, 0))
    assert [(i.label, i.state, i.uptime) for i in done] == [("talker-1", STOPPED, None)]


def test_a_name_two_labels_share_is_refused_and_nothing_is_asked(run: FakeRun) -> None:
    run.running("talker-1", 11)
    run.running("talker-2", 12)
    control, seen = control_of(run)
    with pytest.raises(AmbiguousLabel, match="talker-1, talker-2"):
        control.stop("talker")
    assert run.stopped == [] and seen == []
    assert control.info("talker-2").uptime == 10.0


def test_nothing_is_started_once_the_run_shuts_down(run: FakeRun) -> None:
    run.running("worker-1", 7).returncode = 1
    run.shutting_down = True
    control, seen = control_of(run)
    with pytest.raises(ControlError, match="shutting down"):
        control.start("worker-1")
    assert run.started == [] and seen == []


def test_mute_and_the_logs_go_to_the_printer(run: FakeRun) -> None:
    run.running("talker-1", 5)
    control, seen = control_of(run)
    assert control.mute("talker", by="keys").muted
    assert [(r.label, r.action) for r in seen if isinstance(r, Controlled)] == [
        ("talker-1", "mute")
    ]
    assert control.mute("talker-1").muted and len(seen) == 1  # already muted: nothing said
    with pytest.raises(ControlError, match="writes no log files"):
        control.logs("talker")
