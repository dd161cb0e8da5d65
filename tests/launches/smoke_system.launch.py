"""A small system for `mlaunch test`: two lifecycle nodes brought up in order and a talker.

    mlaunch test tests/launches/smoke_system.launch.py [variant:=VARIANT] [talker_rate:=HZ]

- ok: /robot/camera and /robot/lidar (tests/nodes/lifecycle_node.py) come up camera first
  (a LifecycleSequence); /robot/talker publishes /robot/chatter at talker_rate (10 Hz). The
  file expects /robot/chatter at 10 Hz and /robot/status, which the lidar publishes once active.
- crash: the lidar crashes (status 3) when asked to activate.
- die_later: the talker dies with status 3 one second after it starts.
- ghost: a process declared as Node /robot/ghost that never joins the ROS graph.
- silent: the talker is replaced by tests/nodes/silent.py, which advertises /robot/chatter and
  never publishes on it.
- fail_configure: the lidar refuses to configure.
"""

import os
import sys

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, OpaqueFunction
from launch_ros.actions import LifecycleNode, Node

from mlaunch.commands.smoke import Expect
from mlaunch.launch_ros.lifecycle_sequence import LifecycleSequence

NODES = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "nodes")
VARIANTS = ("ok", "crash", "die_later", "ghost", "silent", "fail_configure")


def program(name, *args):
    return [os.path.join(NODES, name), *args]


def build(context):
    variant = context.launch_configurations["variant"]
    rate = float(context.launch_configurations["talker_rate"])
    lidar_args = {"crash": ["--crash-on-activate"], "fail_configure": ["--fail-configure"]}
    entities = [
        LifecycleNode(
            executable=sys.executable,
            arguments=program("lifecycle_node.py"),
            name="camera",
            namespace="robot",
            exec_name="camera",
        ),
        LifecycleNode(
            executable=sys.executable,
            arguments=program("lifecycle_node.py", *lidar_args.get(variant, [])),
            name="lidar",
            namespace="robot",
            exec_name="lidar",
        ),
        LifecycleSequence(nodes=["/robot/camera", "/robot/lidar"], timeout=15.0),
    ]
    if variant == "silent":
        talker = program("silent.py", "--topic", "chatter")
    elif variant == "die_later":
        talker = program("talker.py", "--die-after", "1.0", "--exit-code", "3")
    else:
        talker = program("talker.py")
    entities.append(
        Node(
            executable=sys.executable,
            arguments=talker,
            name="talker",
            namespace="robot",
            exec_name="talker",
            parameters=[{"rate": rate}],
        )
    )
    if variant == "ghost":
        idle = (
            "import signal, time; signal.signal(signal.SIGINT, lambda *_: exit(0)); time.sleep(60)"
        )
        entities.append(
            Node(
                executable=sys.executable,
                arguments=["-c", idle],
                name="ghost",
                namespace="robot",
                exec_name="ghost",
            )
        )
    return entities


def generate_launch_description():
    return LaunchDescription(
        [
            DeclareLaunchArgument("variant", default_value="ok", choices=VARIANTS),
            DeclareLaunchArgument("talker_rate", default_value="10.0"),
            OpaqueFunction(function=build),
            Expect(topic="/robot/chatter", rate=10.0),
            Expect(topic="/robot/status"),
        ]
    )
