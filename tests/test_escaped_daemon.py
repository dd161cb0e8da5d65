"""A daemon that leaves everything the guard finds a run's processes by (its process group,
the marker in its environment, the run's cgroup) still ends after kill -9 of mlaunch (issue 38,
item 14): while mlaunch lives it is mlaunch's adopted child, and the guard is told its group."""

from __future__ import annotations

import os
import signal
from pathlib import Path

import pytest
from procutil import wait_until
from test_faults import Mlaunch, alive, write_launch

# Once the file argv[3] exists (the run is up: mlaunch is the subreaper from its first turn on;
# a daemon that forks away sooner is found by its marker only, which this one drops),
# double-forks into a session of its own, clears its environment, moves itself to the cgroup
# argv[2] names (out of the run's), says its pid and sleeps.
DAEMON = (
    "import os, sys, time\n"
    "deadline = time.monotonic() + 60\n"
    "while not os.path.exists(sys.argv[3]) and time.monotonic() < deadline:\n"
    "    time.sleep(0.01)\n"
    "if os.fork():\n"
    "    time.sleep(60)\n"
    "    sys.exit(0)\n"
    "os.setsid()\n"
    "if os.fork():\n"
    "    os._exit(0)\n"
    "try:\n"
    "    with open(sys.argv[2], 'w') as f:\n"
    "        f.write(str(os.getpid()))\n"
    "except OSError:\n"
    "    pass\n"
    "with open(sys.argv[1] + '.tmp', 'w') as f:\n"
    "    f.write(str(os.getpid()))\n"
    "os.rename(sys.argv[1] + '.tmp', sys.argv[1])\n"
    "os.execve('/bin/sleep', ['sleep', '60'], {})\n"
)


def cgroup_of(pid: int) -> str:
    return Path(f"/proc/{pid}/cgroup").read_text().strip()


def test_a_daemon_that_left_the_runs_cgroup_ends_after_kill_9(tmp_path: Path) -> None:
    from mlaunch.engine.cgroup import cgroup2_root, own_cgroup

    root, mine = cgroup2_root(), own_cgroup()
    if root is None or mine is None:
        pytest.skip("no cgroup v2 here: a run has no cgroup to leave")
    # Where the test itself is (outside the run's): the daemon moves there.
    away = os.path.join(root, mine.lstrip("/"), "cgroup.procs")
    daemon_pid, go = tmp_path / "daemon.pid", tmp_path / "go"
    launch = write_launch(
        tmp_path,
        [
            "ExecuteProcess(cmd=[PY, '-c', "
            f"{DAEMON!r}, {str(daemon_pid)!r}, {away!r}, {str(go)!r}], name='daemonizer',"
            " sigkill_timeout=0.5)"
        ],
    )
    m = Mlaunch(tmp_path, launch)
    daemon = 0
    try:
        assert wait_until(lambda: "process started with pid" in m.text, 15), m.text
        go.touch()
        assert wait_until(daemon_pid.exists, 15), m.text
        daemon = int(daemon_pid.read_text())
        if "mlaunch-" in cgroup_of(daemon):
            pytest.skip("the daemon could not leave the run's cgroup here (cgroup v2 as root)")
        said = f"sleep [pid {daemon}] left the process that started it"
        assert wait_until(lambda: said in m.text, 15), m.text
        os.kill(m.popen.pid, signal.SIGKILL)
        assert m.wait() == -signal.SIGKILL
        # Before: found by nothing (no marker, no group, no cgroup), it slept on.
        assert wait_until(lambda: not alive(daemon), 20), "the daemon outlived the run"
        assert "died without stopping its processes" in m.stderr()
    finally:
        m.close()
        if daemon and alive(daemon):
            os.kill(daemon, signal.SIGKILL)
