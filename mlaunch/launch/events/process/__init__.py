"""``launch.events.process``: the events of a running process and the matchers that pick one.

Each lives in its own module, named as upstream's; this package only gathers the names
(``mlaunch.launch.gathering``).
"""

from __future__ import annotations

from mlaunch.launch.gathering import Gathered

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.launch.events.process.process_exited import ProcessExited
    from mlaunch.launch.events.process.process_io import ProcessIO
    from mlaunch.launch.events.process.process_matchers import (
        matches_executable,
        matches_name,
        matches_pid,
    )
    from mlaunch.launch.events.process.process_started import ProcessStarted
    from mlaunch.launch.events.process.process_stderr import ProcessStderr
    from mlaunch.launch.events.process.process_stdin import ProcessStdin
    from mlaunch.launch.events.process.process_stdout import ProcessStdout
    from mlaunch.launch.events.process.process_targeted_event import ProcessTargetedEvent
    from mlaunch.launch.events.process.running_process_event import RunningProcessEvent
    from mlaunch.launch.events.process.shutdown_process import ShutdownProcess
    from mlaunch.launch.events.process.signal_process import SignalProcess

_gathered = Gathered(
    globals(),
    {
        "ProcessExited": ".process_exited",
        "ProcessIO": ".process_io",
        "ProcessStarted": ".process_started",
        "ProcessStderr": ".process_stderr",
        "ProcessStdin": ".process_stdin",
        "ProcessStdout": ".process_stdout",
        "ProcessTargetedEvent": ".process_targeted_event",
        "RunningProcessEvent": ".running_process_event",
        "ShutdownProcess": ".shutdown_process",
        "SignalProcess": ".signal_process",
        "matches_executable": ".process_matchers",
        "matches_name": ".process_matchers",
        "matches_pid": ".process_matchers",
    },
    submodules=(
        "process_exited",
        "process_io",
        "process_matchers",
        "process_started",
        "process_stderr",
        "process_stdin",
        "process_stdout",
        "process_targeted_event",
        "running_process_event",
        "shutdown_process",
        "signal_process",
    ),
)
__getattr__ = _gathered.attribute
__dir__ = _gathered.listing

__all__ = [
    "ProcessExited",
    "ProcessIO",
    "ProcessStarted",
    "ProcessStderr",
    "ProcessStdin",
    "ProcessStdout",
    "ProcessTargetedEvent",
    "RunningProcessEvent",
    "ShutdownProcess",
    "SignalProcess",
    "matches_executable",
    "matches_name",
    "matches_pid",
]
