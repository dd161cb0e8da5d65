"""mlaunch's own output on /dev/null, or closed (`>/dev/null`, `>&-`, systemd's
StandardOutput=null), costs the children nothing: a sink that discards is the fastest reader
there is. It was paced as a reader whose speed is unknown, which held every child writing to
the screen to ~0.2 MB/s (150-350 MB/s to a file or a pipe).
"""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest
from procutil import clean_env, mlaunch

FLOOD = """\
import sys
from launch import LaunchDescription
from launch.actions import ExecuteProcess

CODE = 'import sys\\nline = "y" * 99 + "\\\\n"\\nfor i in range(80000):\\n    sys.stdout.write(line)\\n'

def generate_launch_description():
    return LaunchDescription([ExecuteProcess(name='flood', output='screen',
        cmd=[sys.executable, '-c', CODE])])
"""


@pytest.mark.parametrize("sink", ["devnull", "closed"])
def test_a_discarding_stdout_never_throttles_the_children(tmp_path: Path, sink: str) -> None:
    """8 MB to the screen: at 0.2 MB/s it took ~40 s; the deadline is 30 s (about 1 s here)."""
    launch = tmp_path / "flood.launch.py"
    launch.write_text(FLOOD)
    argv = mlaunch(str(launch))
    if sink == "closed":
        argv = ["sh", "-c", 'exec "$@" >&-', "sh", *argv]
    done = subprocess.run(
        argv,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        env=clean_env(ROS_LOG_DIR=str(tmp_path / "log")),
        timeout=30,
    )
    assert done.returncode == 0, done.stderr
    (log,) = [p for p in (tmp_path / "log").glob("*/flood-1.log") if p.parent.name != "latest"]
    assert log.stat().st_size == 80000 * 100  # and every line in the log
