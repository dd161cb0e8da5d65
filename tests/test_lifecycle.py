"""Lifecycle (managed) nodes: sequences resolved from launch files, the loop hand-off, and real
bring-up, events, respawn, reverse deactivation and failure through the rclpy bridge; lifecycle
components (composable_lifecycle_node) brought up once their container loaded them."""

from __future__ import annotations

import os
import re
import selectors
import signal
import subprocess
import sys
import threading
from pathlib import Path

import pytest
from conftest import requires_rclpy
from procutil import Running, clean_env, mlaunch, run_mlaunch, wait_until
from test_composition_ros import requires_composition_interfaces

from mlaunch.launch.actions import DeclareLaunchArgument, GroupAction, LaunchDescription
from mlaunch.launch_ros.lifecycle_sequence import (
    LifecycleSequence,
    SequenceStep,
    sequence_from_arguments,
)
from mlaunch.parts.handoff import LoopCall
from mlaunch.plan.errors import LaunchFileError
from mlaunch.plan.steps import Need
from mlaunch.resolve.resolver import resolve

LAUNCHES = Path(__file__).resolve().parent / "launches"
LIFECYCLE_CONTAINER = Path(__file__).resolve().parent / "nodes" / "lifecycle_container.py"


def _plan(*entities: object, arguments: dict[str, str] | None = None):  # type: ignore[no-untyped-def]
    return resolve(
        LaunchDescription(list(entities)), path=None, arguments=arguments or {}, environ={}
    )


def _sequences(plan) -> list[SequenceStep]:  # type: ignore[no-untyped-def]
    return [s for s in plan.steps if isinstance(s, SequenceStep)]


# --- launch-file side, no ROS needed -------------------------------------------------------------


def test_sequence_names_are_qualified_by_the_pushed_namespace() -> None:
    from mlaunch.launch_ros.actions import PushROSNamespace

    plan = _plan(
        GroupAction(
            [
                PushROSNamespace("robot1"),
                LifecycleSequence(nodes=["map_server", "/global/amcl"], timeout=7),
            ]
        ),
        LifecycleSequence(nodes=["planner"], shutdown_on_failure=False),
    )
    first, second = _sequences(plan)
    assert first.nodes == ("/robot1/map_server", "/global/amcl")
    assert first.timeout == 7.0 and first.shutdown_on_failure
    assert second.nodes == ("/planner",) and not second.shutdown_on_failure


@pytest.mark.parametrize(
    ("nodes", "message"),
    [
        ([], "needs at least one node"),
        (["/a", "a"], "lists '/a' twice"),
        (["2d_lidar"], "'2d_lidar' is not a ROS node name"),
        (["/robot//camera"], "is not a ROS node name"),
    ],
)
def test_bad_sequences_are_located_errors(nodes: list[str], message: str) -> None:
    with pytest.raises(LaunchFileError, match=re.escape(message)) as info:
        _plan(LifecycleSequence(nodes=nodes))
    assert "test_lifecycle.py" in str(info.value)


def test_sequence_of_a_string_and_bad_timeout_are_refused() -> None:
    with pytest.raises(LaunchFileError, match="is a string; give a list"):
        LifecycleSequence(nodes="/a /b")  # type: ignore[arg-type]
    with pytest.raises(LaunchFileError, match="timeout is -1; it must be > 0"):
        _plan(LifecycleSequence(nodes=["/a"], timeout=-1))


def test_sequence_argument_is_the_yaml_and_xml_form() -> None:
    plan = _plan(DeclareLaunchArgument("mlaunch_lifecycle_sequence", default_value="/a, b  /c"))
    step = sequence_from_arguments(plan.arguments, {})
    assert step is not None and step.nodes == ("/a", "/b", "/c")
    override = sequence_from_arguments(plan.arguments, {"mlaunch_lifecycle_sequence": "/z"})
    assert override is not None and override.nodes == ("/z",)
    assert sequence_from_arguments(_plan().arguments, {}) is None
    with pytest.raises(LaunchFileError, match="lists '/a' twice"):
        sequence_from_arguments(plan.arguments, {"mlaunch_lifecycle_sequence": "/a /a"})


def test_plain_plans_attach_nothing_and_lifecycle_plans_attach_without_rclpy() -> None:
    """A plan without lifecycle work gets no manager; one with it gets one, yet imports no rclpy
    until a lifecycle process starts (checked in a fresh interpreter)."""
    from mlaunch.launch.actions import ExecuteProcess, TimerAction

    plain = _plan(ExecuteProcess(cmd=["true"]), TimerAction(period=1.0, actions=[]))
    assert Need.LIFECYCLE not in plain.needs

    code = f"""
import sys
from mlaunch.launch.actions import LaunchDescription, TimerAction
from mlaunch.parts.lifecycle import attach
from mlaunch.engine.output import Printer
from mlaunch.resolve.resolver import resolve
from mlaunch.launch_ros.actions import LifecycleNode
from mlaunch.engine.supervisor import Supervisor
node = LifecycleNode(executable={sys.executable!r}, name="cam", namespace="r", autostart=True)
ld = LaunchDescription([TimerAction(period=5.0, actions=[node])])
plan = resolve(ld, path=None, arguments={{}}, environ={{}})
from mlaunch.plan.steps import Need
assert Need.LIFECYCLE in plan.needs, "a LifecycleNode inside a timer counts"
manager = attach({{}}, Supervisor(plan, Printer(out=lambda b: None), install_signals=False))
assert manager is not None
manager.close()
print("rclpy" in sys.modules)
"""
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=60, env=clean_env()
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "False"


def test_loop_call_runs_callbacks_from_threads_in_the_loop_thread_in_order() -> None:
    selector = selectors.DefaultSelector()
    loop = LoopCall(selector)
    seen: list[tuple[int, str]] = []
    try:

        def post() -> None:
            for i in range(200):

                def record(i: int = i) -> None:
                    seen.append((i, threading.current_thread().name))

                loop.call_soon(record)

        worker = threading.Thread(target=post)
        worker.start()

        def pump() -> bool:
            for key, _ in selector.select(0.05):
                key.data(key.fd)
            return len(seen) == 200

        assert wait_until(pump, 10.0)
        worker.join()
        assert [i for i, _ in seen] == list(range(200))
        assert {name for _, name in seen} == {threading.current_thread().name}
    finally:
        loop.close()
        selector.close()
    loop.call_soon(lambda: seen.append((-1, "")))  # after close: dropped, not an error
    assert len(seen) == 200


# --- real managed nodes --------------------------------------------------------------------------


def _pid(run: Running, label: str) -> int:
    match = run.wait_for(rf"\[{label}\]: process started with pid \[(\d+)\]", 10.0)
    return int(match.group(1))


@requires_rclpy
def test_events_respawn_and_reverse_deactivation(ros_env: dict[str, str]) -> None:
    """autostart, OnStateTransition -> ChangeState (matches_action and matches_node_name), a
    killed autostart node driven back to active, and deactivation in reverse activation order
    before the stop signals."""
    env = clean_env(**ros_env)
    run = Running(mlaunch(str(LAUNCHES / "lifecycle_events.launch.py")), env=env)
    try:
        run.wait_for(r"activate of /robot/camera succeeded; it is now 'active'", 20)
        run.wait_for(r"camera is active: configuring the lidar", 5)
        run.wait_for(r"lidar is configured: activating it", 10)
        run.wait_for(r"activate of /robot/lidar succeeded; it is now 'active'", 10)
        camera = _pid(run, "camera-1")
        os.kill(camera, signal.SIGKILL)
        run.wait_for(r"killed by SIGKILL, restart 1 in 0.5 s", 5)
        # Driven back up: a second successful activate of the camera, after the restart.
        after = run.text.index("restart 1 in 0.5 s")
        run.wait_for(r"(?s)restart 1 in 0\.5 s.*activate of /robot/camera succeeded", 20)
        assert "[camera-1] transition activate: success" in run.text[after:]
        # handle_once: the camera's second activation did not configure the lidar again.
        assert run.text.count("camera is active: configuring the lidar") == 1
        run.signal(signal.SIGINT)
        code = run.finish(30)
    finally:
        run.kill()
    text = run.text
    assert code == 130, text
    assert "transition failed" not in text, text
    tail = text[text.index("shutting down: SIGINT received") :]
    # The camera was activated last (after its respawn), so it is deactivated first, and each
    # node deactivates while alive, before the stop ladder ends it.
    order = [
        tail.index("deactivate of /robot/camera succeeded"),
        tail.index("deactivate of /robot/lidar succeeded"),
    ]
    assert order == sorted(order), tail
    assert tail.index("[lidar-2] transition deactivate: success") < tail.index(
        "[lidar-2]: process has finished cleanly"
    )
    assert tail.index("[camera-1] transition deactivate: success") < tail.index(
        "[camera-1]: process has finished cleanly"
    )


@requires_rclpy
def test_failed_transition_of_a_required_node_ends_the_launch_with_status_1(
    ros_env: dict[str, str],
) -> None:
    done = run_mlaunch(
        str(LAUNCHES / "lifecycle_required.launch.py"), env=clean_env(**ros_env), timeout=40
    )
    out = done.stdout + done.stderr
    assert done.returncode == 1, out
    assert "configure of /robot/camera succeeded; it is now 'inactive'" in out
    assert (
        "transition failed [autostart]: activate of /robot/camera failed:"
        " the node answered success=false; it is now 'inactive'" in out
    )
    assert "shutting down: lifecycle node /robot/camera: activate failed" in out
    assert "[talker-2]: process has finished cleanly" in out


@requires_rclpy
@requires_composition_interfaces
def test_a_composable_lifecycle_node_is_brought_up_once_loaded_and_down_at_shutdown(
    tmp_path: Path, ros_env: dict[str, str]
) -> None:
    """It was an error: "<composable_lifecycle_node> is newer than Jazzy ... and mlaunch does
    not run it yet". Now the component with autostart is configured and activated once its
    container loaded it, and deactivated before the container is stopped; the one without
    autostart is loaded and left unconfigured."""
    plugin = "mlaunch_test::LifecycleComponent"
    path = tmp_path / "components.launch.xml"
    path.write_text(
        f"""<launch>
<node_container exec="{sys.executable}" args="{LIFECYCLE_CONTAINER}" name="box" namespace=""
    output="screen">
  <composable_lifecycle_node pkg="mlaunch_test" plugin="{plugin}" name="cam"
      namespace="/robot" autostart="true"/>
  <composable_lifecycle_node pkg="mlaunch_test" plugin="{plugin}" name="idle"/>
</node_container>
</launch>
"""
    )
    run = Running(mlaunch(str(path)), env=clean_env(**ros_env))
    try:
        run.wait_for(r"Loaded node '/idle' in container '/box'", 30)
        run.wait_for(r"activate of /robot/cam succeeded; it is now 'active'", 30)
        run.wait_for(r"/robot/cam transition activate: success", 10)
        run.signal(signal.SIGINT)
        code = run.finish(30)
    finally:
        run.kill()
    text = run.text
    assert code == 130, text
    assert "transition failed" not in text, text
    assert "configure of /robot/cam succeeded; it is now 'inactive'" in text
    assert "/idle transition" not in text, text
    tail = text[text.index("shutting down: SIGINT received") :]
    assert "deactivate of /robot/cam succeeded" in tail, tail
    assert tail.index("/robot/cam transition deactivate: success") < tail.index(
        "process has finished cleanly"
    ), tail
