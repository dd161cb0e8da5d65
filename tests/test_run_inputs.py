"""What a run decides once and passes on (issue 31 point 5): its package search, and whether
launch's own ROS clock follows simulated time."""

from __future__ import annotations

from pathlib import Path

from mlaunch.app import pipeline
from mlaunch.app.options import parse_options
from mlaunch.launch.launch_context import LaunchContext
from mlaunch.launch.planning import StandalonePlanner
from mlaunch.launch_ros.actions.ros_timer import ROSTimer
from mlaunch.launch_ros.actions.set_use_sim_time import SetUseSimTime
from mlaunch.plan.steps import StartTimer, ros_clock

LAUNCH = """\
from launch import LaunchDescription
from launch.actions import LogInfo


def generate_launch_description():
    return LaunchDescription([LogInfo(msg="hi")])
"""


def test_a_run_makes_its_package_search_once_and_passes_it(tmp_path: Path) -> None:
    file = tmp_path / "one.launch.py"
    file.write_text(LAUNCH)
    opts = parse_options([str(file), "--print"])
    path, search = pipeline.find_target(opts)
    assert search.launch_file == path == str(file)
    description = pipeline.load_file(opts, path, search)
    _plan, options, _labels = pipeline.resolve_for_run(
        opts, path, description, temp_dir=str(tmp_path), log_dir="", search=search
    )
    assert options.packages is search


def _timer_steps(context: LaunchContext) -> list[StartTimer]:
    planner = context.planner
    assert isinstance(planner, StandalonePlanner)
    return [step for step in planner.plan.steps if isinstance(step, StartTimer)]


def test_the_run_s_ros_clock_says_whether_ros_time_is_simulated() -> None:
    context = LaunchContext()
    timer = ROSTimer(period=1.0, actions=[])
    timer.visit(context)
    (step,) = _timer_steps(context)
    assert step.ros_clock is ros_clock(context.run_state)
    assert not step.on_sim_time
    # A SetUseSimTime after the timer counts, as launch_ros's clock follows /clock from then on.
    SetUseSimTime(True).visit(context)
    assert step.on_sim_time
    # A snapshot (a timer's or handler's body) shares the run's clock.
    assert ros_clock(context.snapshot().run_state) is step.ros_clock
