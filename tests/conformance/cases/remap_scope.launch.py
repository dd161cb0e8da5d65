# SetRemap inside a scoped group: launch_ros extends the remap list in place, so once a global
# remap exists before the group, the group's rules reach the nodes after it too.
from launch import LaunchDescription
from launch.actions import GroupAction
from launch_ros.actions import Node, SetRemap


def rec(name, **kw):
    return Node(package="conf_pkg", executable="recorder", name=name, **kw)


def generate_launch_description():
    return LaunchDescription(
        [
            GroupAction([SetRemap(src="first", dst="kept_inside"), rec("first_group")]),
            rec("before_any_global"),
            SetRemap(src="/tf", dst="tf"),
            GroupAction([SetRemap(src="cmd", dst="cmd_vel"), rec("in_group")]),
            rec("after_group", remappings=[("own", "rule")]),
        ]
    )
