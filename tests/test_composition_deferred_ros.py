"""Loads written in timers and event handlers reach real rclpy containers; a dead container's
loads end cleanly at Ctrl-C.

``mlaunch FILE`` runs against the recording container (tests/nodes/recording_container.py,
which prints each request it receives) and mlaunch's container stand-in (which hosts
robot_state_publisher's component and refuses other plugins with its reason, so a refusal
proves the request was sent). Every wait has a deadline; the run ends on SIGINT with 130.
"""

from __future__ import annotations

import json
import os
import signal
import sys
import textwrap
from pathlib import Path
from typing import Any

import pytest
from conftest import requires_rclpy
from procutil import Running, clean_env, mlaunch, pid_alive, wait_until
from test_composition_ros import RECORDER, requires_composition_interfaces
from test_standin_nodes import URDF

pytestmark = [requires_rclpy, requires_composition_interfaces, pytest.mark.timeout(120)]

PY = sys.executable

HANDLERS_PY = """
    from launch import LaunchDescription
    from launch.actions import ExecuteProcess, RegisterEventHandler, TimerAction
    from launch.event_handlers import OnProcessStart
    from launch_ros.actions import ComposableNodeContainer, LoadComposableNodes, PushROSNamespace
    from launch_ros.descriptions import ComposableNode


    def generate_launch_description():
        rec = ExecuteProcess(
            cmd=[PY, RECORDER, '--ros-args', '-r', '__node:=rec'], name='rec', output='screen')
        box = ComposableNodeContainer(
            package='rclcpp_components', executable='component_container', name='dbox',
            namespace='', composable_node_descriptions=[ComposableNode(
                package='robot_state_publisher',
                plugin='robot_state_publisher::RobotStatePublisher',
                parameters=[{'robot_description': URDF}])])
        return LaunchDescription([
            rec,
            # A load and a container with its own nodes, both started when rec starts.
            RegisterEventHandler(OnProcessStart(target_action=rec, on_start=[
                LoadComposableNodes(target_container='/rec', composable_node_descriptions=[
                    ComposableNode(package='p', plugin='p::Start', name='on_start')]),
                box,
            ])),
            TimerAction(period=0.5, actions=[
                PushROSNamespace('t'),
                LoadComposableNodes(target_container='/rec', composable_node_descriptions=[
                    ComposableNode(package='p', plugin='p::Timer', name='in_timer',
                                   parameters=[{'x': 1}])]),
            ]),
            # Into the container the handler above started, given as the action.
            RegisterEventHandler(OnProcessStart(target_action=box, on_start=[
                LoadComposableNodes(target_container=box, composable_node_descriptions=[
                    ComposableNode(package='composition', plugin='composition::Talker',
                                   name='talker')]),
            ])),
        ])
"""

TIMER_XML = """
    <launch>
      <executable cmd="{py} {recorder} --ros-args -r __node:=rec" name="rec" output="screen"/>
      <timer period="0.5">
        <push_ros_namespace namespace="t"/>
        <load_composable_node target="/rec">
          <composable_node pkg="p" plugin="p::Timer" name="in_timer">
            <param name="x" value="1"/>
          </composable_node>
        </load_composable_node>
        <node_container pkg="rclcpp_components" exec="component_container" name="dbox"
                        namespace="">
          <composable_node pkg="composition" plugin="composition::Talker" name="talker"/>
        </node_container>
      </timer>
    </launch>
"""

REFUSED = (
    "Failed to load node 'talker' of type 'composition::Talker' in container '/dbox':"
    " mlaunch's container stand-in cannot load plugin 'composition::Talker'"
)


def start(path: Path, env: dict[str, str]) -> Running:
    return Running(mlaunch(str(path)), env=env)


def run_env(ros_env: dict[str, str], tmp_path: Path) -> dict[str, str]:
    keys = ("ROS_DOMAIN_ID", "ROS_AUTOMATIC_DISCOVERY_RANGE", "RMW_IMPLEMENTATION")
    env = clean_env(**{k: ros_env[k] for k in keys})
    env["ROS_LOG_DIR"] = str(tmp_path / "log")
    return env


def recorded(run: Running) -> list[dict[str, Any]]:
    """The requests the recording container printed (its lines in mlaunch's output)."""
    out = []
    for line in run.text.splitlines():
        head, _, rest = line.partition("] ")
        if head.startswith("[rec") and rest.startswith("{"):
            out.append(json.loads(rest))
    return out


def stop(run: Running) -> int:
    """Ctrl-C: the run ends by itself within the deadline, with the usual status."""
    run.signal(signal.SIGINT)
    try:
        return run.finish(timeout=20)
    finally:
        run.kill()


def test_loads_in_a_timer_and_in_handlers_reach_their_containers(
    ros_env: dict[str, str], tmp_path: Path
) -> None:
    path = tmp_path / "handlers.launch.py"
    head = f"PY = {PY!r}\nRECORDER = {RECORDER!r}\nURDF = {URDF!r}\n"
    path.write_text(head + textwrap.dedent(HANDLERS_PY))
    run = start(path, run_env(ros_env, tmp_path))
    try:
        run.wait_for(r"Loaded node '/on_start' in container '/rec'", 60)
        run.wait_for(r"Loaded node '/t/in_timer' in container '/rec'", 60)
        run.wait_for(r"Loaded node '/robot_state_publisher' in container '/dbox'", 60)
        run.wait_for(REFUSED, 60)
        assert wait_until(lambda: len(recorded(run)) >= 2, 10), run.text
    finally:
        code = stop(run)
    assert code == 130, run.text
    requests = {r["node_name"]: r for r in recorded(run)}
    assert sorted(requests) == ["in_timer", "on_start"]
    # Resolved when the timer fired: its pushed namespace and its parameter.
    assert requests["in_timer"]["node_namespace"] == "/t"
    assert requests["in_timer"]["parameters"] == [["x", 2, 1]]
    assert "nothing in this run carries it out" not in run.text


def test_a_timer_tag_loads_into_a_running_and_a_new_container(
    ros_env: dict[str, str], tmp_path: Path
) -> None:
    path = tmp_path / "timer.launch.xml"
    path.write_text(textwrap.dedent(TIMER_XML).format(py=PY, recorder=RECORDER))
    run = start(path, run_env(ros_env, tmp_path))
    try:
        run.wait_for(r"Loaded node '/t/in_timer' in container '/rec'", 60)
        # The container the timer started is pushed into /t; its load goes to its full name.
        run.wait_for(REFUSED.replace("'/dbox'", "'/t/dbox'"), 60)
    finally:
        code = stop(run)
    assert code == 130, run.text
    (request,) = recorded(run)
    assert (request["node_name"], request["node_namespace"]) == ("in_timer", "/t")


DEAD_PY = """
    from launch import LaunchDescription
    from launch_ros.actions import LoadComposableNodes, Node
    from launch_ros.descriptions import ComposableNode


    def generate_launch_description():
        return LaunchDescription([
            # A "container" that never serves load_node; the test kills it.
            Node(executable=PY, name='dead', arguments=['-c', 'import time; time.sleep(300)']),
            LoadComposableNodes(target_container='/dead', composable_node_descriptions=[
                ComposableNode(package='p', plugin='p::A', name='a'),
                ComposableNode(package='p', plugin='p::B', name='b'),
            ]),
        ])
"""


def test_a_dead_containers_loads_are_said_and_ctrl_c_ends_the_run(
    ros_env: dict[str, str], tmp_path: Path
) -> None:
    """As launch_ros: the loads keep waiting for the service (the launch stays up, as ros2
    launch does) until Ctrl-C abandons them, one line each; mlaunch also says when the
    container died with loads pending."""
    path = tmp_path / "dead.launch.py"
    path.write_text(f"PY = {PY!r}\n" + textwrap.dedent(DEAD_PY))
    run = start(path, run_env(ros_env, tmp_path))
    try:
        pid = int(run.wait_for(r"\[[^]]+-1\]: process started with pid \[(\d+)\]", 30)[1])
        os.kill(pid, signal.SIGKILL)
        run.wait_for(
            r"container '/dead' exited before it loaded node 'a' of type 'p::A', node 'b' of"
            r" type 'p::B': the loads wait",
            30,
        )
        assert not pid_alive(pid)
        assert run.proc.poll() is None, "the pending loads keep the launch up, as in ros2 launch"
    finally:
        code = stop(run)
    assert code == 130, run.text
    for name, plugin in (("a", "p::A"), ("b", "p::B")):
        assert (
            "Abandoning wait for the '/dead/_container/load_node' service, due to shutdown:"
            f" node '{name}' of type '{plugin}' was never loaded"
        ) in run.text


OPAQUE_PY = """
    from launch import LaunchDescription
    from launch.actions import ExecuteProcess, OpaqueFunction, RegisterEventHandler
    from launch.event_handlers import OnProcessStart
    from launch_ros.actions import LoadComposableNodes
    from launch_ros.descriptions import ComposableNode


    def load(context):
        return [LoadComposableNodes(target_container='/rec', composable_node_descriptions=[
            ComposableNode(package='p', plugin='p::Opaque', name='opaque'),
            ComposableNode(package='p', plugin='p::Again', name='opaque')])]


    def generate_launch_description():
        rec = ExecuteProcess(
            cmd=[PY, RECORDER, '--ros-args', '-r', '__node:=rec'], name='rec', output='screen')
        return LaunchDescription([
            rec,
            RegisterEventHandler(OnProcessStart(
                target_action=rec, on_start=[OpaqueFunction(function=load)])),
        ])
"""


def test_a_load_only_a_function_makes_attaches_the_driver_when_it_comes(
    ros_env: dict[str, str], tmp_path: Path
) -> None:
    """Nothing before the run shows a load (the plan does not need the driver): the first
    LoadComponents handed over attaches it. A second node of the same name is warned about
    under the container's name, as launch_ros counts loaded names with the nodes'."""
    path = tmp_path / "opaque.launch.py"
    path.write_text(f"PY = {PY!r}\nRECORDER = {RECORDER!r}\n" + textwrap.dedent(OPAQUE_PY))
    run = start(path, run_env(ros_env, tmp_path))
    try:
        run.wait_for(
            r"\[WARNING\] \[/rec\]: there are now at least 2 nodes with the name /opaque"
            r" created within this launch context",
            60,
        )
    finally:
        code = stop(run)
    assert code == 130, run.text
    assert run.text.count("Loaded node '/opaque' in container '/rec'") == 2
    assert [r["plugin_name"] for r in recorded(run)] == ["p::Opaque", "p::Again"]


def test_the_driver_abandons_its_loads_at_shutdown_and_leaves_no_thread(
    ros_env: dict[str, str],
) -> None:
    """In-process: a load for a container nobody starts keeps the run up until it shuts down;
    then the wait is abandoned (said) and ``close`` leaves no load thread behind."""
    import threading

    from test_supervision import Harness

    from mlaunch.launch_ros.composition import LoadComponents
    from mlaunch.launch_ros.load_request import LoadRequest
    from mlaunch.parts.components import ComponentDriver
    from mlaunch.plan.records import HandedOff, Record
    from mlaunch.plan.steps import Plan

    request = LoadRequest("p", "p::A", "a")
    h = Harness(Plan(steps=[LoadComponents("x.launch.py:1", "/nobody", (request,))]))
    driver = ComponentDriver(h.sup)

    def on_record(record: Record) -> None:
        if isinstance(record, HandedOff):  # the driver has its thread waiting by now
            h.sup.schedule(0.0, h.shutdown)

    h.sup.records.subscribe(on_record)
    try:
        assert h.run() == 0
    finally:
        driver.close()
    h.printer.flush()
    left = [t for t in threading.enumerate() if t.name.startswith("load ") or t.name == "rtps"]
    assert not left
    assert (
        "Abandoning wait for the '/nobody/_container/load_node' service, due to shutdown:"
        " node 'a' of type 'p::A' was never loaded"
    ) in h.text


def test_a_launch_service_loads_components_of_a_description_included_while_running(
    ros_env: dict[str, str],
) -> None:
    """launch.LaunchService (launch_testing and launch_pytest run on it) attaches the same
    LoadNode driver, also for a load whose description is included after the run began."""
    import threading

    from test_launch_service import Screen

    from mlaunch.app.launch_service import LaunchService
    from mlaunch.launch.actions import ExecuteProcess, LaunchDescription
    from mlaunch.launch_ros.actions import LoadComposableNodes
    from mlaunch.launch_ros.descriptions.composable_node import ComposableNode

    screen = Screen()
    service = LaunchService(screen=screen)
    recorder = ExecuteProcess(
        cmd=[PY, RECORDER, "--ros-args", "-r", "__node:=rec"], name="rec", output="screen"
    )
    service.include_launch_description(LaunchDescription([recorder]))
    seen: list[str] = []

    def drive() -> None:
        """From another thread, as a test runner does: include the load once rec is up."""
        try:
            if not screen.wait_for("recording container ready", 60):
                return
            seen.append("ready")
            load = LoadComposableNodes(
                target_container="/rec",
                composable_node_descriptions=[
                    ComposableNode(package="p", plugin="p::S", name="svc")
                ],
            )
            service.include_launch_description(LaunchDescription([load]))
            if screen.wait_for("Loaded node '/svc' in container '/rec'", 60):
                seen.append("loaded")
        finally:
            service.shutdown()

    thread = threading.Thread(target=drive, daemon=True)
    thread.start()
    code = service.run()  # the main thread, as launch requires
    thread.join(30)
    assert seen == ["ready", "loaded"], screen.data.decode()
    assert code == 0, screen.data.decode()
    assert not [t for t in threading.enumerate() if t.name.startswith("load ")]


IN_FLIGHT_PY = """
    from launch import LaunchDescription
    from launch_ros.actions import LoadComposableNodes, Node
    from launch_ros.descriptions import ComposableNode


    def generate_launch_description():
        return LaunchDescription([
            # Dies on the request for p::Die, after receiving it and before answering.
            Node(executable=PY, name='rec', arguments=[RECORDER, '--exit-on', 'p::Die']),
            LoadComposableNodes(target_container='/rec', composable_node_descriptions=[
                ComposableNode(package='p', plugin='p::Die', name='a'),
                ComposableNode(package='p', plugin='p::B', name='b'),
            ]),
        ])
"""


def test_a_container_that_dies_with_a_load_in_flight(
    ros_env: dict[str, str], tmp_path: Path
) -> None:
    """The request sent stays unanswered (launch_ros waits for the answer until shutdown, and
    never sends the next one); Ctrl-C abandons both, each with its own line."""
    path = tmp_path / "in_flight.launch.py"
    path.write_text(f"PY = {PY!r}\nRECORDER = {RECORDER!r}\n" + textwrap.dedent(IN_FLIGHT_PY))
    run = start(path, run_env(ros_env, tmp_path))
    try:
        run.wait_for(
            r"container '/rec' exited before it loaded node 'a' of type 'p::Die', node 'b' of"
            r" type 'p::B'",
            60,
        )
        assert run.proc.poll() is None, "the pending loads keep the launch up, as in ros2 launch"
    finally:
        code = stop(run)
    assert code == 130, run.text
    assert (
        "Abandoning wait for the '/rec/_container/load_node' service response, due to shutdown:"
        " node 'a' of type 'p::Die' may not have been loaded"
    ) in run.text
    assert (
        "Abandoning wait for the '/rec/_container/load_node' service, due to shutdown:"
        " node 'b' of type 'p::B' was never loaded"
    ) in run.text


def test_a_load_that_raises_ends_the_launch_with_1(ros_env: dict[str, str], tmp_path: Path) -> None:
    """An integer LoadNode's int64 cannot carry fails when the request is sent: launch's run
    loop catches the exception, shuts down and exits 1 (checked with the reference)."""
    path = tmp_path / "raises.launch.py"
    path.write_text(
        f"PY = {PY!r}\nRECORDER = {RECORDER!r}\n"
        + textwrap.dedent(
            """
            from launch import LaunchDescription
            from launch.actions import ExecuteProcess
            from launch_ros.actions import LoadComposableNodes
            from launch_ros.descriptions import ComposableNode


            def generate_launch_description():
                return LaunchDescription([
                    ExecuteProcess(cmd=[PY, RECORDER, '--ros-args', '-r', '__node:=rec'],
                                   name='rec', output='screen'),
                    LoadComposableNodes(target_container='/rec', composable_node_descriptions=[
                        ComposableNode(package='p', plugin='p::A', name='a',
                                       parameters=[{'x': 2**70}])]),
                ])
            """
        )
    )
    run = start(path, run_env(ros_env, tmp_path))
    try:
        code = run.finish(60)
    finally:
        run.kill()
    assert code == 1, run.text
    assert "[ERROR] [launch_ros.actions.load_composable_nodes]: Loading into container '/rec'" in (
        run.text
    )
    assert "shutting down: loading into container '/rec' failed" in run.text


SMOKE_PY = """
    from launch import LaunchDescription
    from launch.actions import TimerAction
    from launch_ros.actions import ComposableNodeContainer, LoadComposableNodes
    from launch_ros.descriptions import ComposableNode


    def generate_launch_description():
        box = ComposableNodeContainer(
            package='rclcpp_components', executable='component_container', name='tbox',
            namespace='')
        return LaunchDescription([
            box,
            TimerAction(period=0.5, actions=[
                LoadComposableNodes(target_container=box, composable_node_descriptions=[
                    ComposableNode(package='robot_state_publisher',
                                   plugin='robot_state_publisher::RobotStatePublisher',
                                   name='rsp', parameters=[{'robot_description': URDF}]),
                    ComposableNode(package='composition', plugin='composition::Talker',
                                   name='talker'),
                ]),
            ]),
        ])
"""


def test_mlaunch_test_expects_the_nodes_a_timer_loads(
    ros_env: dict[str, str], tmp_path: Path
) -> None:
    """mlaunch test treats components loaded later as nodes the graph must show: the one the
    stand-in hosts passes, the plugin it refuses fails the test."""
    import subprocess

    path = tmp_path / "smoke.launch.py"
    path.write_text(f"URDF = {URDF!r}\n" + textwrap.dedent(SMOKE_PY))
    done = subprocess.run(
        mlaunch("test", str(path), "--timeout", "10"),
        capture_output=True,
        text=True,
        env=run_env(ros_env, tmp_path),
        timeout=120,
    )
    out = done.stdout + done.stderr
    assert done.returncode == 1, out
    rows = [line.split(None, 1) for line in out.splitlines() if "is in the ROS graph" in line]
    ok = [rest for status, rest in rows if status == "ok"]
    failed = [rest for status, rest in rows if status == "FAIL"]
    assert any("node /rsp is in the ROS graph" in r for r in ok), out
    assert [r for r in failed if "node /talker is in the ROS graph" in r], out


def test_the_driver_loads_through_rclpy_when_rtps_cannot_start(
    ros_env: dict[str, str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """No RTPS port of the domain free (or no UDP at all): the run says so once and its loads
    go through rclpy, as they did before the RTPS client."""
    from test_supervision import Harness

    from mlaunch.launch_ros.composition import LoadComponents
    from mlaunch.launch_ros.load_request import LoadRequest
    from mlaunch.parts import rtps
    from mlaunch.parts.components import ComponentDriver
    from mlaunch.plan.steps import Plan

    def no_port(self: rtps.Participant) -> None:
        raise OSError("no free RTPS port from 7410 for domain 0: address in use")

    monkeypatch.setattr(rtps.Participant, "_bind_unicast", no_port)
    request = LoadRequest("p", "p::A", "a")
    h = Harness(Plan(steps=[LoadComponents("x.launch.py:1", "/nobody", (request,))]))
    driver = ComponentDriver(h.sup)
    try:
        assert driver.loader.link.name == "rclpy"
    finally:
        driver.close()
    h.printer.flush()
    assert "the RTPS loader could not start (no free RTPS port" in h.text
    assert "loading through rclpy" in h.text


def test_an_unknown_loader_choice_is_warned_and_rclpy_loads(
    ros_env: dict[str, str], monkeypatch: pytest.MonkeyPatch
) -> None:
    from test_supervision import Harness

    from mlaunch.launch_ros.composition import LoadComponents
    from mlaunch.launch_ros.load_request import LoadRequest
    from mlaunch.parts.components import ComponentDriver
    from mlaunch.plan.steps import Plan

    monkeypatch.setenv("MLAUNCH_LOADER", "rcply")
    request = LoadRequest("p", "p::A", "a")
    h = Harness(Plan(steps=[LoadComponents("x.launch.py:1", "/nobody", (request,))]))
    driver = ComponentDriver(h.sup)
    try:
        assert driver.loader.link.name == "rclpy"
    finally:
        driver.close()
    h.printer.flush()
    assert "MLAUNCH_LOADER='rcply' is not 'rtps' or 'rclpy': loading through rclpy" in h.text
