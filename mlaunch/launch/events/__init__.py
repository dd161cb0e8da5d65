"""``launch.events``: the events of launch, with ROS 2's names, and the matchers handlers use to
pick processes.

Each event lives in its own module, named as upstream's (the events of a running process in
``launch.events.process``); the base class is ``launch.event``. This package only gathers the
names (``mlaunch.launch.gathering``).
"""

from __future__ import annotations

from mlaunch.launch.gathering import Gathered

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.launch.event import Event
    from mlaunch.launch.events.execution_complete import ExecutionComplete
    from mlaunch.launch.events.include_launch_description import IncludeLaunchDescription
    from mlaunch.launch.events.matchers import matches_action
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
    from mlaunch.launch.events.shutdown import Shutdown
    from mlaunch.launch.events.timer_event import TimerEvent

_gathered = Gathered(
    globals(),
    {
        "Event": "mlaunch.launch.event",
        "ExecutionComplete": ".execution_complete",
        "IncludeLaunchDescription": ".include_launch_description",
        "ProcessExited": ".process.process_exited",
        "ProcessIO": ".process.process_io",
        "ProcessStarted": ".process.process_started",
        "ProcessStderr": ".process.process_stderr",
        "ProcessStdin": ".process.process_stdin",
        "ProcessStdout": ".process.process_stdout",
        "ProcessTargetedEvent": ".process.process_targeted_event",
        "RunningProcessEvent": ".process.running_process_event",
        "Shutdown": ".shutdown",
        "ShutdownProcess": ".process.shutdown_process",
        "SignalProcess": ".process.signal_process",
        "TimerEvent": ".timer_event",
        "matches_action": ".matchers",
        "matches_executable": ".process.process_matchers",
        "matches_name": ".process.process_matchers",
        "matches_pid": ".process.process_matchers",
    },
    submodules=(
        "execution_complete",
        "include_launch_description",
        "matchers",
        "process",
        "shutdown",
        "timer_event",
    ),
)
__getattr__ = _gathered.attribute
__dir__ = _gathered.listing

__all__ = [
    "Event",
    "ExecutionComplete",
    "IncludeLaunchDescription",
    "ProcessExited",
    "ProcessIO",
    "ProcessStarted",
    "ProcessStderr",
    "ProcessStdin",
    "ProcessStdout",
    "ProcessTargetedEvent",
    "RunningProcessEvent",
    "Shutdown",
    "ShutdownProcess",
    "SignalProcess",
    "TimerEvent",
    "matches_action",
    "matches_executable",
    "matches_name",
    "matches_pid",
    "process",
]
