"""``kill -9`` of mlaunch *and* its guard leaves the params folder; a later run's guard removes
it, and never a live run's or another user's (issue 27, item 12)."""

from __future__ import annotations

import fcntl
import os
import signal
import subprocess
from pathlib import Path

from procutil import wait_until
from test_faults import PY, SLEEPER, Mlaunch, assert_nothing_left, proc, write_launch


def guard_of(pid: int) -> int:
    """The pid of mlaunch ``pid``'s guard (a fork of it, retitled ``launch-guard``)."""

    def find() -> int | None:
        for entry in os.listdir("/proc"):
            if not entry.isdigit():
                continue
            try:
                stat = Path(f"/proc/{entry}/stat").read_text()
                cmdline = Path(f"/proc/{entry}/cmdline").read_bytes()
            except OSError:
                continue
            ppid = int(stat[stat.rfind(")") + 2 :].split()[1])
            if ppid == pid and cmdline.startswith(b"launch-guard"):
                return int(entry)
        return None

    assert wait_until(lambda: find() is not None, 10), "no guard found"
    found = find()
    assert found is not None
    return found


def later_run(tmp: Path, launch: Path) -> None:
    env = dict(os.environ, TMPDIR=str(tmp))
    env.pop("MLAUNCH_RUN_ID", None)
    done = subprocess.run(
        [PY, "-m", "mlaunch", str(launch), "--print"], capture_output=True, env=env, timeout=30
    )
    assert done.returncode == 0, done.stderr


def test_a_later_run_removes_the_folder_of_a_run_killed_with_its_guard(tmp_path: Path) -> None:
    launch = write_launch(tmp_path, [proc(SLEEPER, "plain")])
    m = Mlaunch(tmp_path, launch)
    try:
        (run_id, child), *_ = m.wait_ups(1)
        guard = guard_of(m.popen.pid)
        folders = list(m.tmp.glob("mlaunch-*"))
        assert len(folders) == 1
        os.kill(guard, signal.SIGKILL)  # the guard first: nobody is left to clean up
        m.popen.send_signal(signal.SIGKILL)
        assert m.wait() == -signal.SIGKILL
        os.kill(child, signal.SIGKILL)  # not survivable: the child runs on (docs/faults.md)
        assert_nothing_left(run_id, [child])
        assert folders[0].is_dir()  # before: left there for good
        later_run(m.tmp, launch)
        assert wait_until(lambda: not folders[0].exists(), 10), "the dead run's folder is left"
    finally:
        m.close()


def test_the_sweep_spares_live_runs_locked_folders_and_other_users(tmp_path: Path) -> None:
    launch = write_launch(tmp_path, [proc(SLEEPER, "plain")])
    m = Mlaunch(tmp_path, launch)
    try:
        (run_id, child), *_ = m.wait_ups(1)
        (live,) = list(m.tmp.glob("mlaunch-*"))
        # A run in another PID namespace: its PID is not ours to see, but it holds the lock.
        hidden = m.tmp / "mlaunch-999999999-0123abcd"
        hidden.mkdir(mode=0o700)
        (hidden / "params.yaml").write_text("a: 1\n")
        lock = os.open(hidden, os.O_RDONLY | os.O_DIRECTORY)
        fcntl.flock(lock, fcntl.LOCK_EX)
        # Another user's dead run (root can make one): never ours to remove.
        other = m.tmp / "mlaunch-999999998-0123abcd"
        other.mkdir(mode=0o700)
        if os.getuid() == 0:
            os.chown(other, 65534, 65534)
        # A dead run of ours, unlocked: removed.
        dead = m.tmp / "mlaunch-999999997-0123abcd"
        dead.mkdir(mode=0o700)
        (dead / "params.yaml").write_text("a: 1\n")
        later_run(m.tmp, launch)
        assert wait_until(lambda: not dead.exists(), 10)
        assert live.is_dir() and (hidden / "params.yaml").exists()
        assert other.is_dir() == (os.getuid() == 0)
        os.close(lock)
        m.popen.send_signal(signal.SIGINT)
        assert m.wait() == 130
        assert_nothing_left(run_id, [child])
    finally:
        m.close()
