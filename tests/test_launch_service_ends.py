"""Nothing outlives a LaunchService, however it is driven: run(), run_async() cancelled or timed
out, a task dropped unfinished, run_in_thread() at interpreter exit, a service never run. Each
test starts real processes and checks, with deadlines, that none of them (nor the guard, nor
the run's thread) is left, and that they were stopped by the ladder (SIGINT first)."""

from __future__ import annotations

import asyncio
import gc
import os
import signal
import subprocess
import sys
import textwrap
import threading
from pathlib import Path

import pytest
from procutil import REPO, clean_env, pid_alive, wait_until
from test_launch_service import DEADLINE, Screen, python

from mlaunch.app.launch_service import LaunchService
from mlaunch.launch.actions import LaunchDescription

# Prints its pid, then waits; SIGINT is answered with a word, so a test sees the ladder's first
# step reached it (a SIGKILL leaves no word).
POLITE = textwrap.dedent(
    """
    import os, signal, sys, time
    def bye(*_):
        print('polite bye', flush=True)
        sys.exit(0)
    signal.signal(signal.SIGINT, bye)
    print(f'polite-pid={os.getpid()}', flush=True)
    while True:
        time.sleep(1)
    """
)


def descendants() -> set[int]:
    """The live processes below this one (children, their children ...), from /proc."""
    parents: dict[int, int] = {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            stat = Path(f"/proc/{entry}/stat").read_text()
        except OSError:
            continue
        fields = stat.rsplit(")", 1)[1].split()
        if fields[0] != "Z":
            parents[int(entry)] = int(fields[1])
    found: set[int] = set()
    frontier = {os.getpid()}
    while frontier:
        frontier = {pid for pid, ppid in parents.items() if ppid in frontier} - found
        found |= frontier
    return found


def service_threads() -> list[threading.Thread]:
    return [t for t in threading.enumerate() if t.name == "LaunchService"]


def assert_nothing_left(before: set[int]) -> None:
    """Every process started since ``before`` has ended, and no run thread is left."""
    left: set[int] = set()

    def gone() -> bool:
        left.clear()
        left.update(descendants() - before)
        return not left and not service_threads()

    assert wait_until(gone, DEADLINE), f"left behind: pids {left}, threads {service_threads()}"


def started(screen: Screen) -> int:
    """The pid the POLITE child printed."""
    assert screen.wait_for("polite-pid=")
    return int(screen.data.split(b"polite-pid=", 1)[1].split()[0])


def polite_service() -> tuple[LaunchService, Screen]:
    screen = Screen()
    service = LaunchService(screen=screen)
    service.include_launch_description(LaunchDescription([python(POLITE, name="polite")]))
    return service, screen


def test_run_then_shutdown_from_a_thread_leaves_nothing() -> None:
    before = descendants()
    service, screen = polite_service()

    def stop() -> None:
        started(screen)
        service.shutdown()

    threading.Thread(target=stop, daemon=True).start()
    assert service.run() == 0
    assert b"polite bye" in screen.data
    assert_nothing_left(before)


def test_cancelled_run_async_stops_its_processes_and_returns_1() -> None:
    before = descendants()
    service, screen = polite_service()

    async def main() -> int:
        task = asyncio.ensure_future(service.run_async())
        pid = await asyncio.to_thread(started, screen)
        assert pid_alive(pid)
        task.cancel()
        return await task

    assert asyncio.run(main()) == 1
    assert b"shutting down: run task was canceled" in screen.data
    assert b"polite bye" in screen.data
    assert_nothing_left(before)


def test_run_async_timed_out_by_wait_for_stops_its_processes() -> None:
    before = descendants()
    service, screen = polite_service()

    async def main() -> None:
        task = asyncio.ensure_future(service.run_async())
        await asyncio.to_thread(started, screen)
        # wait_for cancels the task and waits for it: the launch has ended when it returns.
        try:
            await asyncio.wait_for(task, 0.1)
        except TimeoutError:
            pass
        assert task.done()

    asyncio.run(main())
    assert b"polite bye" in screen.data
    assert_nothing_left(before)


def test_a_second_cancel_kills_what_ignores_the_ladder() -> None:
    before = descendants()
    screen = Screen()
    service = LaunchService(screen=screen)
    stubborn = (
        "import os, signal, time\n"
        "signal.signal(signal.SIGINT, signal.SIG_IGN)\n"
        "signal.signal(signal.SIGTERM, signal.SIG_IGN)\n"
        "print(f'polite-pid={os.getpid()}', flush=True)\n"
        "time.sleep(60)"
    )
    service.include_launch_description(
        LaunchDescription([python(stubborn, sigterm_timeout="20", sigkill_timeout="20")])
    )

    async def main() -> int:
        task = asyncio.ensure_future(service.run_async())
        await asyncio.to_thread(started, screen)
        task.cancel()
        await asyncio.to_thread(screen.wait_for, "shutting down")
        task.cancel()  # the ladder would wait 20 s before SIGTERM: this one kills at once
        return await asyncio.wait_for(task, DEADLINE)

    assert asyncio.run(main()) == 1
    assert_nothing_left(before)


def test_a_dropped_run_async_task_shuts_the_launch_down() -> None:
    before = descendants()
    service, screen = polite_service()
    loop = asyncio.new_event_loop()
    task = loop.create_task(service.run_async())
    loop.run_until_complete(asyncio.to_thread(started, screen))
    loop.close()  # the task never finishes: a test that failed half way
    del task
    gc.collect()  # the task's coroutine is closed as it is collected
    assert wait_until(lambda: b"polite bye" in screen.data, DEADLINE), screen.data
    assert_nothing_left(before)


# How a script leaves its launch running as it ends: a thread, or a run_async task whose loop
# is left behind unfinished.
LEAVE = {
    "thread": "service.run_in_thread()\nassert seen.wait(20)",
    "task": (
        "import asyncio\n"
        "loop = asyncio.new_event_loop()\n"
        "task = loop.create_task(service.run_async())\n"
        "assert loop.run_until_complete(asyncio.to_thread(seen.wait, 20))"
    ),
}


@pytest.mark.parametrize("way", sorted(LEAVE))
def test_a_run_still_going_at_interpreter_exit_is_stopped(tmp_path: Path, way: str) -> None:
    script = tmp_path / "leaves.py"
    script.write_text(
        textwrap.dedent(
            f"""
            import sys, threading
            sys.path.insert(0, {str(REPO)!r})
            from mlaunch.app.launch_service import LaunchService
            from mlaunch.launch.actions import ExecuteProcess, LaunchDescription
            seen = threading.Event()
            def screen(data):
                sys.stdout.buffer.write(data)
                sys.stdout.flush()
                if b"polite-pid=" in data:
                    seen.set()
            service = LaunchService(screen=screen)
            service.include_launch_description(LaunchDescription([ExecuteProcess(
                cmd=[sys.executable, "-c", {POLITE!r}], output="screen")]))
            """
        )
        + LEAVE[way]
        + "\n"
    )
    done = subprocess.run(
        [sys.executable, str(script)],
        capture_output=True,
        text=True,
        env=clean_env(),
        timeout=DEADLINE,
        stdin=subprocess.DEVNULL,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    pid = int(done.stdout.split("polite-pid=", 1)[1].split()[0])
    assert "shutting down: the Python interpreter is exiting" in done.stdout, done.stdout
    assert "polite bye" in done.stdout, done.stdout
    assert not pid_alive(pid)


def test_a_service_never_run_starts_nothing() -> None:
    before = descendants()
    threads = set(threading.enumerate())
    service, _ = polite_service()
    service.shutdown()  # not running: nothing to do
    del service
    gc.collect()
    assert descendants() == before
    assert set(threading.enumerate()) == threads


@pytest.mark.parametrize("way", ["idle", "required"])
def test_a_run_that_ends_by_itself_leaves_nothing(way: str) -> None:
    before = descendants()
    screen = Screen()
    service = LaunchService(screen=screen)
    entities = [python(POLITE, name="polite")]
    if way == "idle":
        entities = [python("print('done')")]
    else:
        entities.append(python("raise SystemExit(2)", required=True))
    service.include_launch_description(LaunchDescription(entities))
    assert service.run() == (0 if way == "idle" else 1)
    assert_nothing_left(before)


def test_two_threaded_runs_and_the_hosts_own_child_keep_their_exits() -> None:
    """Each run waits for its own children only: neither takes the other's exits (both hung
    so), nor the exit status of a child the host script started itself."""
    before = descendants()
    services = []
    for word in ("one", "two"):
        service = LaunchService(screen=Screen())
        service.include_launch_description(
            LaunchDescription([python(f"import time; time.sleep(0.3); print({word!r})")])
        )
        services.append(service)
    threads = [service.run_in_thread() for service in services]
    own = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(0.5); exit(7)"])
    for thread in threads:
        thread.join(DEADLINE)
    assert [thread.is_alive() for thread in threads] == [False, False]
    assert [service.return_code for service in services] == [0, 0]
    assert own.wait(DEADLINE) == 7
    assert_nothing_left(before)


class HostDeadline(BaseException):
    """What a test runner raises from its own SIGALRM handler (pytest-timeout's Failed is a
    BaseException too: no ``except Exception`` on the way may swallow it)."""


def test_an_exception_raised_into_run_stops_its_processes_through_the_ladder() -> None:
    """A host's own signal handler may raise into run() (pytest-timeout's signal method does):
    the processes get the stop ladder (SIGINT first) before the exception goes on up."""
    before = descendants()
    service, screen = polite_service()

    def deadline(signum: int, frame: object) -> None:
        raise HostDeadline("the host's deadline")

    def raise_when_up() -> None:
        started(screen)
        os.kill(os.getpid(), signal.SIGALRM)

    old = signal.signal(signal.SIGALRM, deadline)
    try:
        threading.Thread(target=raise_when_up, daemon=True).start()
        with pytest.raises(HostDeadline, match="the host's deadline"):
            service.run()
    finally:
        signal.signal(signal.SIGALRM, old)
    assert b"shutting down: the run was interrupted (HostDeadline)" in screen.data
    assert b"polite bye" in screen.data
    assert_nothing_left(before)
