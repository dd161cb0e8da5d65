"""``launch_testing.util``: process lookup for assertions, and KeepAliveProc."""

from __future__ import annotations

import sys

from mlaunch.launch.actions.execute_process import ExecuteProcess
from mlaunch.launch_testing.util.proc_lookup import (
    NO_CMD_ARGS,
    NoMatchingProcessException,
    resolveProcesses,
)

# Sleeps until stopped; SIGINT (launch's first stop signal) and SIGTERM end it with status 0.
_KEEP_ALIVE_SCRIPT = """
import signal, time
signal.signal(signal.SIGTERM, lambda *_: exit(0))
try:
    while True:
        time.sleep(3600)
except KeyboardInterrupt:
    pass
"""


def KeepAliveProc() -> ExecuteProcess:
    """A process that does nothing until it is stopped, so the launch outlives the ones tested.

    launch_test ends the launch itself once the active tests are done; when every process under
    test ends on its own, this one keeps the launch up until then. It exits 0 when stopped, so
    ``assertExitCodes`` over every process still passes.
    """
    return ExecuteProcess(cmd=[sys.executable, "-c", _KEEP_ALIVE_SCRIPT])


__all__ = ["NO_CMD_ARGS", "KeepAliveProc", "NoMatchingProcessException", "resolveProcesses"]
