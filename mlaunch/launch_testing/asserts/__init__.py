"""``launch_testing.asserts``: exit codes and output of the processes under test."""

from __future__ import annotations

from mlaunch.launch_testing.asserts.assert_exit_codes import (
    EXIT_OK,
    EXIT_SIGINT,
    EXIT_SIGKILL,
    EXIT_SIGQUIT,
    EXIT_SIGSEGV,
    assertExitCodes,
)
from mlaunch.launch_testing.asserts.assert_output import (
    assertDefaultStream,
    assertInStderr,
    assertInStdout,
    assertInStream,
)
from mlaunch.launch_testing.asserts.assert_sequential_output import (
    SequentialTextChecker,
    assertSequentialStdout,
)
from mlaunch.launch_testing.util.proc_lookup import NO_CMD_ARGS

__all__ = [
    "EXIT_OK",
    "EXIT_SIGINT",
    "EXIT_SIGKILL",
    "EXIT_SIGQUIT",
    "EXIT_SIGSEGV",
    "NO_CMD_ARGS",
    "SequentialTextChecker",
    "assertDefaultStream",
    "assertExitCodes",
    "assertInStderr",
    "assertInStdout",
    "assertInStream",
    "assertSequentialStdout",
]
