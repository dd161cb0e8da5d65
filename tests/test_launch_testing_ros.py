"""launch_testing_ros: its output filter knowing an RMW implementation's own lines, files marked
``rostest`` run by its runner under pytest, and DataRepublisher with MessagePump on rclpy."""

from __future__ import annotations

import threading
from pathlib import Path

import pytest
from conftest import requires_rclpy
from procutil import clean_env
from test_launch_pytest import run_pytest

from mlaunch.launch_testing_ros import DataRepublisher, MessagePump
from mlaunch.launch_testing_ros.tools import basic_output_filter
from mlaunch.launch_testing_ros.tools.output import get_rmw_output_filter

DEADLINE = 20.0


def _register(prefix: Path, resource_type: str, name: str, content: str) -> None:
    folder = prefix / "share" / "ament_index" / "resource_index" / resource_type
    folder.mkdir(parents=True, exist_ok=True)
    (folder / name).write_text(content)


def test_output_filter_drops_what_the_rmw_implementation_registered(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    _register(tmp_path, "rmw_output_prefixes", "rmw_chatty", "[chatty]\nRTPS:")
    _register(tmp_path, "rmw_output_patterns", "rmw_chatty", r"\d+ discovery .*")
    monkeypatch.setenv("AMENT_PREFIX_PATH", str(tmp_path))
    assert get_rmw_output_filter("rmw_chatty", "prefixes") == ["[chatty]", "RTPS:"]
    assert get_rmw_output_filter("rmw_quiet", "patterns") == []
    output = "pid 7\n[chatty] up\nkeep me\nRTPS: x\n12 discovery done\nrc 0\n"
    assert basic_output_filter(filtered_rmw_implementation="rmw_chatty")(output) == "keep me\n"
    assert basic_output_filter()(output) == "[chatty] up\nkeep me\nRTPS: x\n12 discovery done\n"
    with pytest.raises(TypeError, match='Unsupported filter_type "lines"'):
        get_rmw_output_filter("rmw_chatty", "lines")


ROSTEST = """\
import sys
import unittest

import launch
import launch.actions
import launch_testing.actions
import pytest


@pytest.mark.rostest
def generate_test_description():
    return launch.LaunchDescription([
        launch.actions.ExecuteProcess(cmd=[sys.executable, '-c', 'print("hello ros")']),
        launch_testing.actions.ReadyToTest(),
    ])


class TestOutput(unittest.TestCase):
    def test_hello(self, proc_output):
        proc_output.assertWaitFor('hello ros', stream='stdout', timeout=20)
"""

# Writes which runner each collected item will use, where the test can read it.
CONFTEST = """\
def pytest_collection_modifyitems(items):
    with open('runners.txt', 'w') as f:
        for item in items:
            f.write(item.runner_cls.__module__ + '.' + item.runner_cls.__name__ + '\\n')
"""


def test_files_marked_rostest_run_with_the_ros_runner(tmp_path: Path) -> None:
    (tmp_path / "conftest.py").write_text(CONFTEST)
    path = tmp_path / "hello_rostest.py"
    path.write_text(ROSTEST)
    found, output = run_pytest(path, tmp_path, clean_env())
    assert found == [["hello_rostest", "passed"]], output
    runners = (tmp_path / "runners.txt").read_text().split()
    assert runners == ["mlaunch.launch_testing_ros.test_runner.LaunchTestRunner"]


@requires_rclpy
def test_data_republisher_and_message_pump(ros_env: dict[str, str]) -> None:
    import rclpy
    from std_msgs.msg import String

    context = rclpy.Context()
    rclpy.init(context=context)
    node = rclpy.create_node("republisher_test", context=context)
    received: list[str] = []
    got = threading.Event()

    def on_out(message: String) -> None:
        received.append(message.data)
        got.set()

    def shout(message: String) -> String | None:
        return None if message.data == "drop" else String(data=message.data.upper())

    republisher = DataRepublisher(node, "words_in", "words_out", String, shout)
    node.create_subscription(String, "words_out", on_out, 10)
    publisher = node.create_publisher(String, "words_in", 10)
    pump = MessagePump(node, context=context)
    pump.start()
    try:
        for _ in range(int(DEADLINE / 0.1)):  # publish until discovery has matched both ends
            publisher.publish(String(data="drop"))
            publisher.publish(String(data="hi"))
            if got.wait(0.1):
                break
        assert received and received[0] == "HI"
        assert republisher.get_num_received() > republisher.get_num_republished() >= 1
        assert all(m.data == "hi" for m in republisher.get_republished())
    finally:
        republisher.shutdown()
        pump.stop()
        node.destroy_node()
        context.try_shutdown()


# A managed node that says each transition on stderr (as rclpy's logger does), and a launch_test
# that drives it with ChangeState and waits for its lines by its LifecycleNode action.
LIFECYCLE_TALKER = """\
import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.lifecycle import Node, TransitionCallbackReturn


class Talker(Node):
    def on_configure(self, state):
        self.get_logger().info('configured now')
        return TransitionCallbackReturn.SUCCESS

    def on_activate(self, state):
        self.get_logger().info('active now')
        return super().on_activate(state)


rclpy.init()
node = Talker('lc_talker')
try:
    rclpy.spin(node)
except (KeyboardInterrupt, ExternalShutdownException):
    pass
"""

LIFECYCLE_TEST = """\
import sys
import unittest

import launch
import launch.actions
import launch.events
import launch.event_handlers
import launch_ros.actions
import launch_ros.event_handlers
import launch_ros.events.lifecycle
import launch_testing.actions
import lifecycle_msgs.msg
import pytest


def change(node, transition):
    return launch.actions.EmitEvent(event=launch_ros.events.lifecycle.ChangeState(
        lifecycle_node_matcher=launch.events.matches_action(node), transition_id=transition))


@pytest.mark.launch_test
def generate_test_description():
    talker = launch_ros.actions.LifecycleNode(
        executable=sys.executable, arguments=[TALKER], name='lc_talker', namespace='',
        output='screen')
    T = lifecycle_msgs.msg.Transition
    return launch.LaunchDescription([
        talker,
        launch.actions.RegisterEventHandler(launch.event_handlers.OnProcessStart(
            target_action=talker, on_start=[change(talker, T.TRANSITION_CONFIGURE)])),
        launch.actions.RegisterEventHandler(launch_ros.event_handlers.OnStateTransition(
            target_lifecycle_node=talker, goal_state='inactive',
            entities=[change(talker, T.TRANSITION_ACTIVATE)])),
        launch_testing.actions.ReadyToTest(),
    ]), {'talker': talker}


class TestLifecycle(unittest.TestCase):
    def test_each_transition_is_said(self, proc_output, talker):
        proc_output.assertWaitFor('configured now', process=talker, timeout=20)
        proc_output.assertWaitFor('active now', process=talker, timeout=20)
"""


@requires_rclpy
def test_output_of_a_lifecycle_node_is_matched_by_its_action(
    tmp_path: Path, ros_env: dict[str, str]
) -> None:
    # Issue 38, item 17 (ros2/demos' lifecycle_py test_lifecycle): the launch_test's runner did
    # not drive lifecycle nodes ("event ChangeState has no handler"), so the node never
    # configured, said nothing, and assertWaitFor(process=node) found no process: an ERROR.
    talker = tmp_path / "lc_talker.py"
    talker.write_text(LIFECYCLE_TALKER)
    path = tmp_path / "test_lc_launch.py"
    path.write_text(LIFECYCLE_TEST.replace("[TALKER]", f"[{str(talker)!r}]"))
    found, output = run_pytest(path, tmp_path, clean_env(**ros_env))
    assert found == [["test_lc_launch", "passed"]], output
    assert "has no handler" not in output, output
