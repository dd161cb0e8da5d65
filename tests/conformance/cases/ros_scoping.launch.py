# PushRosNamespace, SetParameter, SetRemap inside scoped and forwarding groups
from launch import LaunchDescription
from launch.actions import GroupAction
from launch_ros.actions import Node, PushRosNamespace, SetParameter, SetRemap


def rec(name, **kw):
    return Node(package="conf_pkg", executable="recorder", name=name, **kw)


def generate_launch_description():
    return LaunchDescription(
        [
            SetParameter(name="global_p", value=1),
            GroupAction(
                [
                    PushRosNamespace("ns1"),
                    SetParameter(name="scoped_p", value="s"),
                    SetRemap(src="a", dst="b"),
                    rec("in_scope"),
                    GroupAction([PushRosNamespace("inner"), rec("nested", namespace="rel")]),
                    rec("abs", namespace="/absolute"),
                ]
            ),
            GroupAction(
                [PushRosNamespace("fwd"), SetParameter(name="fwd_p", value=True)], scoped=False
            ),
            rec("after_groups"),
            GroupAction(
                [rec("forwarding_kept")], forwarding=False, launch_configurations={"x": "1"}
            ),
        ]
    )
