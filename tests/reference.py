"""Where the reference ros2 launch (ROS 2 Jazzy's own launch system, the oracle of the
differential tests) is built: ``MLAUNCH_REFERENCE`` (what ``.ci/run`` sets, from
``scripts/reference``), else ``~/.cache/ros2-launch-jazzy`` (where its setup.sh builds it by
default). The tests that need it skip with ``MISSING`` where it is not built."""

from __future__ import annotations

import os
from pathlib import Path

HOME = Path(os.environ.get("MLAUNCH_REFERENCE") or Path.home() / ".cache" / "ros2-launch-jazzy")
ENV_SH = HOME / "env.sh"
SOURCES = HOME / "src"
MISSING = (
    f"the reference ros2 launch is not built at {HOME} (scripts/reference builds it, and"
    " MLAUNCH_REFERENCE=FOLDER names it; .ci/run does both)"
)
