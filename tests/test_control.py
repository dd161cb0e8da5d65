"""The control core (mlaunch.parts.control) driven in-process on a live Supervisor.

Each request is made from inside the loop when a child says something (the harness's hooks),
as the control socket and the --status keys make them; the test then reads the records, the
record stream and the printer's words. No sleeps: children wait for files the test creates.
"""

from __future__ import annotations

from pathlib import Path
from typing import TypeVar

import pytest
from test_supervision import Harness, make_spec, plan_from, write_launch

from mlaunch.engine.process_state import RUNNING, STOPPED
from mlaunch.parts.control import ControlError, ProcessInfo, UnknownLabel
from mlaunch.plan.records import Controlled, Exited, Record, RespawnScheduled, Started
from mlaunch.plan.steps import RespawnPolicy

E = TypeVar("E", bound=Record)


class Seen:
    """The records of the run's record stream that these tests look at."""

    def __init__(self, h: Harness) -> None:
        self.events: list[Record] = []
        h.sup.records.subscribe(self._on)

    def _on(self, record: Record) -> None:
        if isinstance(record, (Started, Exited, RespawnScheduled, Controlled)):
            self.events.append(record)

    def of(self, kind: type[E]) -> list[E]:
        return [e for e in self.events if isinstance(e, kind)]


# Says "ready" (not a word of Python's KeyboardInterrupt traceback), then waits to be stopped.
SLEEPER = 'import time; print("ready", flush=True); time.sleep(60)'


def sleeper(name: str) -> str:
    """SLEEPER saying ``ready-NAME``, for a hook on one process of several."""
    return f'import time; print("ready-{name}", flush=True); time.sleep(60)'


ALWAYS = RespawnPolicy(mode="always", delay=0.0, backoff=2.0, max_delay=30.0)


def test_stop_is_said_as_a_user_stop_and_respawn_leaves_it_down() -> None:
    h = Harness(
        [make_spec("worker", sleeper("worker"), respawn=ALWAYS), make_spec("other", SLEEPER)]
    )
    seen = Seen(h)
    stopped: list[ProcessInfo] = []

    def after_stop(info: ProcessInfo) -> None:
        # The respawn decision is taken before the exit is handed out: it would be seen by now.
        stopped.append(info)
        h.sup.schedule(0.0, h.shutdown)

    h.when(b"ready-worker", lambda *_: h.control().stop("worker", by="ctl", done=after_stop))
    assert h.run() == 0  # Ctrl-C-less shutdown: nothing failed
    worker = h.messages("worker")
    assert "stop asked by the user (mlaunch ctl)" in worker
    assert any(m.startswith("process stopped by the user [pid ") for m in worker), worker
    assert not any("died" in m for m in worker)
    assert not seen.of(RespawnScheduled)
    assert len([e for e in seen.of(Started) if e.process.label == "worker"]) == 1
    record = h.sup.states["worker"]
    assert record.state == STOPPED and record.outcome == "stopped by the user"
    assert not record.failed
    assert stopped and stopped[0].state == STOPPED and stopped[0].pid == 0


def test_start_after_a_stop_and_restart_keep_the_label_without_backoff() -> None:
    h = Harness([make_spec("worker", SLEEPER, respawn=ALWAYS)])
    seen = Seen(h)
    infos: list[ProcessInfo] = []
    ups = [0]

    def on_up(label: str, line: bytes) -> None:
        ups[0] += 1
        control = h.control()
        if ups[0] == 1:  # the first instance: stop it, then start it again
            control.stop("worker", done=lambda info: control.start("worker", done=infos.append))
        elif ups[0] in (2, 3):
            control.restart("worker", done=infos.append)
        else:
            h.sup.schedule(0.0, h.shutdown)
        if ups[0] < 4:
            h.when(b"ready", on_up)

    h.when(b"ready", on_up)
    assert h.run() == 0
    starts = [e.process for e in seen.of(Started)]
    assert [p.label for p in starts] == ["worker"] * 4
    assert [p.restarts for p in starts] == [0, 1, 2, 3]
    assert len({p.pid for p in starts}) == 4
    assert not seen.of(RespawnScheduled)  # no respawn, so no backoff delay either
    assert [i.restarts for i in infos] == [1, 2, 3]
    assert all(i.state == RUNNING and i.pid for i in infos)
    record = h.sup.states["worker"]
    assert record.restarts == 3 and record.user_starts == 3 and record.streak == 0
    words = h.messages("worker")
    assert words.count("restart asked by the user") == 2
    restarted = f"process stopped by the user for a restart [pid {starts[1].pid}, SIGINT]"
    assert words.count(restarted) == 1
    # Every exit reached the stream with its return code, as launch's OnProcessExit sees it.
    assert [e.code for e in seen.of(Exited)][:3] == [-2, -2, -2]


def test_user_restarts_do_not_use_up_respawn_retries() -> None:
    crash_after_restart = """
        import os, sys, time
        print("ready", flush=True)
        if os.environ.get("CRASH"): sys.exit(3)
        time.sleep(60)
    """
    policy = RespawnPolicy(mode="on-failure", delay=0.0, max_retries=1)
    h = Harness([make_spec("w", crash_after_restart, respawn=policy)])
    ups = [0]

    def on_up(label: str, line: bytes) -> None:
        ups[0] += 1
        if ups[0] <= 2:
            h.control().restart("w")
            h.when(b"ready", on_up)
        else:
            h.sup.schedule(0.0, h.shutdown)

    h.when(b"ready", on_up)
    assert h.run() == 0
    record = h.sup.states["w"]
    assert record.restarts == 2 and record.user_starts == 2
    assert "giving up" not in h.text


def test_mute_keeps_output_off_the_screen_but_in_the_log(tmp_path: Path) -> None:
    one, two = tmp_path / "one", tmp_path / "two"
    code = f"""
        import os, time
        def wait(path):
            while not os.path.exists(path):
                time.sleep(0.01)
        print("first line", flush=True)
        wait({str(one)!r})
        print("muted line", flush=True)
        wait({str(two)!r})
        print("last line", flush=True)
    """
    (tmp_path / "logs").mkdir()
    h = Harness([make_spec("talker", code)], log_dir=str(tmp_path / "logs"))
    seen = Seen(h)
    tails: list[list[str]] = []

    def mute(label: str, line: bytes) -> None:
        assert h.control().mute("talker", by="keys").muted
        one.touch()

    def unmute(label: str, line: bytes) -> None:
        tails.append(h.control().logs("talker", 2))
        assert not h.control().unmute("talker").muted
        two.touch()

    h.when(b"first line", mute)
    h.when(b"muted line", unmute)
    assert h.run() == 0
    screen = h.text
    assert "[talker] first line" in screen and "[talker] last line" in screen
    assert "muted line" not in screen
    log = (tmp_path / "logs" / "talker.log").read_text()
    assert log == "first line\nmuted line\nlast line\n"
    assert tails == [["first line", "muted line"]]
    assert "output muted by the user (--status keys); still written to talker.log" in screen
    assert "output unmuted by the user" in screen
    assert [e.action for e in seen.of(Controlled)] == ["mute", "unmute"]


def test_a_user_stop_of_a_required_process_does_not_end_or_fail_the_run() -> None:
    h = Harness([make_spec("boss", sleeper("boss"), required=True), make_spec("other", SLEEPER)])
    boss_gone = [False]

    def stop(*_: object) -> None:
        h.control().stop("boss", done=lambda info: boss_gone.__setitem__(0, True))

    h.when(b"ready-boss", stop)

    def check_then_stop() -> None:
        if boss_gone[0]:
            assert not h.sup.shutting_down  # the required process did not end the launch
            assert h.sup.states["other"].state == RUNNING
            h.shutdown()
        else:
            h.sup.schedule(0.02, check_then_stop)

    h.sup.schedule(0.02, check_then_stop)
    assert h.run() == 0


def test_a_launch_whose_processes_the_user_stopped_stays_up() -> None:
    h = Harness([make_spec("only", SLEEPER)])
    seen: list[bool] = []

    def check() -> None:
        # The loop has asked whether it is idle since the exit: it is not, the user may start it.
        seen.append(h.sup.shutting_down)
        h.shutdown()

    def stopped(info: ProcessInfo) -> None:
        h.sup.schedule(0.0, check)

    h.when(b"ready", lambda *_: h.control().stop("only", done=stopped))
    assert h.run() == 0
    assert seen == [False]
    assert "shutting down: test" in h.text


def test_on_process_exit_handlers_see_a_user_stop(tmp_path: Path) -> None:
    path = write_launch(
        tmp_path,
        """
        from launch.actions import LogInfo, RegisterEventHandler
        from launch.event_handlers import OnProcessExit
        def generate_launch_description():
            worker = ExecuteProcess(
                cmd=[PY, '-c', 'import time; print("ready", flush=True); time.sleep(60)'],
                name='worker')
            return LaunchDescription([
                worker,
                RegisterEventHandler(OnProcessExit(target_action=worker, on_exit=[
                    LogInfo(msg='exit seen'), Shutdown(reason='worker is gone')])),
            ])
        """,
    )
    h = Harness(plan_from(path, tmp_path))
    h.when(b"ready", lambda label, line: h.control().stop(label))
    assert h.run() == 0  # the handler's Shutdown ends the launch, without a failure
    assert "exit seen" in h.text
    assert "shutting down: worker is gone" in h.text


def test_a_stop_cancels_a_pending_respawn() -> None:
    policy = RespawnPolicy(mode="always", delay=30.0)
    h = Harness([make_spec("crash", "import sys; sys.exit(1)", respawn=policy)])
    infos: list[ProcessInfo] = []

    def on_exit(record: Record) -> None:
        if isinstance(record, RespawnScheduled):
            pending = h.control().info("crash")
            assert pending.restart_in is not None and 29 < pending.restart_in <= 30
            assert pending.uptime is None and pending.state == "restarting"
            h.control().stop("crash", done=infos.append)
            h.sup.schedule(0.0, h.shutdown)

    h.sup.records.subscribe(on_exit)
    assert h.run() == 0
    assert h.elapsed < 5
    assert infos and infos[0].state == STOPPED and infos[0].restart_in is None
    assert h.sup.states["crash"].state == STOPPED


def test_bad_requests_are_clear_errors_and_change_nothing() -> None:
    h = Harness([make_spec("talker", sleeper("talker")), make_spec("listener", SLEEPER)])
    errors: list[str] = []

    def ask(label: str, line: bytes) -> None:
        control = h.control()
        for request in (
            lambda: control.stop("talkr"),
            lambda: control.start("talker"),
            lambda: control.logs("talker"),
        ):
            try:
                request()
            except ControlError as e:
                errors.append(str(e))
        with pytest.raises(UnknownLabel) as info:
            control.mute("lisener")
        assert info.value.close == ["listener"] and info.value.exit_code == 2
        h.sup.schedule(0.0, h.shutdown)

    h.when(b"ready-talker", ask)
    assert h.run() == 0
    assert errors[0].startswith("no process 'talkr' in this run; did you mean 'talker'?")
    assert "(processes: talker, listener)" in errors[0]
    assert errors[1].startswith("talker is already running [pid ")
    assert errors[2] == "logs: this run writes no log files: no lines kept"
    assert h.sup.states["talker"].restarts == 0


def test_an_unknown_label_lists_at_most_twenty() -> None:
    labels = [f"node{i:03d}-{i}" for i in range(250)]
    text = str(UnknownLabel("node000-x", labels))
    assert "did you mean 'node000-0'" in text
    assert text.endswith("node019-19 and 230 more (mlaunch ctl list shows them))")


def test_list_shows_every_label() -> None:
    h = Harness([make_spec("a", sleeper("a")), make_spec("b", "print('ready')")])
    rows: list[dict[str, object]] = []

    def listing() -> None:
        if h.sup.states.get("b") is None or h.sup.states["b"].state == RUNNING:
            h.sup.schedule(0.02, listing)
            return
        rows.extend(info.as_dict() for info in h.control().processes())
        h.shutdown()

    h.sup.schedule(0.02, listing)
    assert h.run() == 0
    assert [r["label"] for r in rows] == ["a", "b"]
    a, b = rows
    assert a["state"] == "running" and a["pid"] and isinstance(a["uptime"], float)
    assert b["state"] == "finished" and b["pid"] == 0 and b["uptime"] is None
    assert b["outcome"] == "finished cleanly" and a["muted"] is False
