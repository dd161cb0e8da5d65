"""The six causes of issue 24, each where mlaunch read a roslaunch file unlike roslaunch:
included ``*.launch.xml`` fragments, one unholdable value in a ``<rosparam>`` load, names that
point into another namespace, untyped substituted values, globals set in an included file,
and node ``args`` split before substitution."""

from __future__ import annotations

import os
from pathlib import Path

from procutil import install_package
from test_convert import converted
from test_roslaunch import (
    PREFIX,
    by_label,
    globals_of,
    package,
    params,
    plan_of,
    summarize,
    warnings_text,
    write,
)


def test_an_included_launch_xml_fragment_is_read_as_roslaunch_xml(tmp_path: Path) -> None:
    package(tmp_path, "demo_cfg")
    main = write(
        tmp_path,
        "launch/main.launch",
        """
        <launch>
          <include file="$(dirname)/includes/part.launch.xml">
            <arg name="who" value="fragment"/>
          </include>
        </launch>
        """,
    )
    write(
        tmp_path,
        "launch/includes/part.launch.xml",
        """
        <launch>
          <arg name="who"/>
          <node pkg="mlaunch_demo" type="talker" name="$(arg who)"
                args="$(find demo_cfg)/cfg.yaml"/>
        </launch>
        """,
    )
    (talker,) = plan_of(main).processes()
    assert talker.argv[1] == str(tmp_path / "demo_cfg" / "cfg.yaml")
    assert "__node:=fragment" in talker.argv


def test_one_unholdable_value_drops_only_its_key(tmp_path: Path) -> None:
    (tmp_path / "costmap.yaml").write_text(
        "footprint: [[-0.1, -0.1], [-0.1, 0.1], [0.2, 0.0]]\n"
        "plugins:\n  - {name: static_layer, type: 'costmap_2d::StaticLayer'}\n"
        "inflation_radius: 1.0\nrolling_window: true\nscan: {topic: scan, marking: true}\n"
    )
    path = write(
        tmp_path,
        "nav.launch",
        """
        <launch>
          <node pkg="mlaunch_demo" type="talker" name="move_base">
            <rosparam file="$(dirname)/costmap.yaml" command="load" ns="local_costmap"/>
          </node>
          <rosparam file="$(dirname)/costmap.yaml" command="load" ns="global_costmap"/>
        </launch>
        """,
    )
    plan = plan_of(path)
    own = params(by_label(plan)["talker"])
    assert own["local_costmap.inflation_radius"] == 1.0
    assert own["local_costmap.rolling_window"] is True
    assert own["local_costmap.scan.topic"] == "scan"
    # nav2 reads a footprint as text: the list of points is written as that text
    assert own["local_costmap.footprint"] == "[[-0.1, -0.1], [-0.1, 0.1], [0.2, 0.0]]"
    assert "local_costmap.plugins" not in own
    text = warnings_text(plan)
    located = "nav.launch:2: <rosparam> at line 3: parameter local_costmap/plugins: a list of maps"
    assert located in text
    assert "nav.launch:5: parameter global_costmap/plugins: a list of maps or lists" in text
    assert "footprint" not in text


def test_untyped_substituted_values_are_typed_as_roslaunch_types_them(tmp_path: Path) -> None:
    path = write(
        tmp_path,
        "types.launch",
        """
        <launch>
          <arg name="glob" default="[*]"/>
          <arg name="n" default="3"/>
          <arg name="x" default="1.5"/>
          <arg name="flag" default="TRUE"/>
          <arg name="word" default="yes"/>
          <arg name="big" default="1_000"/>
          <node pkg="mlaunch_demo" type="talker" name="t">
            <param name="glob" value="$(arg glob)"/>
            <param name="n" value="$(arg n)"/>
            <param name="x" value="$(arg x)"/>
            <param name="flag" value="$(arg flag)"/>
            <param name="word" value="$(arg word)"/>
            <param name="big" value="$(arg big)"/>
            <param name="padded" value=" $(arg n) "/>
          </node>
        </launch>
        """,
    )
    (talker,) = plan_of(path).processes()
    own = params(talker)
    assert own == {
        "glob": "[*]",
        "n": 3,
        "x": 1.5,
        "flag": True,
        "word": "yes",
        "big": "1_000",
        "padded": 3,
    }
    assert params(plan_of(path, {"flag": "False", "n": "abc"}).processes()[0])["flag"] is False


def test_node_args_are_substituted_then_split_like_a_shell(tmp_path: Path) -> None:
    path = write(
        tmp_path,
        "args.launch",
        """
        <launch>
          <arg name="empty" default=""/>
          <arg name="two" default="-a  -b"/>
          <arg name="quoted" default="'one word' x"/>
          <node pkg="mlaunch_demo" type="talker" name="t"
                args="$(arg empty) --first $(arg two) $(arg quoted) $(arg empty)"/>
        </launch>
        """,
    )
    (talker,) = plan_of(path).processes()
    assert list(talker.argv[1 : talker.argv.index("--ros-args")]) == [
        "--first",
        "-a",
        "-b",
        "one word",
        "x",
    ]


def test_names_are_rerooted_by_ros1_name_rules(tmp_path: Path) -> None:
    (tmp_path / "ctrl.yaml").write_text(
        "rrbot:\n  jsc:\n    type: joint_state_controller/JointStateController\n"
        "    publish_rate: 50\n"
    )
    path = write(
        tmp_path,
        "sim.launch",
        """
        <launch>
          <param name="gazebo/enable_ros_network" value="true"/>
          <rosparam file="$(dirname)/ctrl.yaml" command="load"/>
          <param name="shared" value="1"/>
          <node pkg="mlaunch_demo" type="talker" name="gazebo"/>
          <node pkg="mlaunch_demo" type="talker" name="urdf_spawner"/>
          <group ns="rrbot">
            <node pkg="mlaunch_demo" type="listener" name="controller_spawner"/>
          </group>
        </launch>
        """,
    )
    nodes = {s.node.name: s for s in plan_of(path).processes() if s.node}
    # /gazebo/x is node /gazebo's private ~x; /rrbot/... reaches /rrbot's nodes by relative name
    assert globals_of(nodes["gazebo"]) == {"shared": "1"}
    assert params(nodes["gazebo"]) == {"enable_ros_network": True}
    assert globals_of(nodes["urdf_spawner"]) == {"shared": "1"}
    assert globals_of(nodes["controller_spawner"]) == {
        "shared": "1",
        "jsc.type": "joint_state_controller/JointStateController",
        "jsc.publish_rate": "50",
    }


def test_a_global_set_in_an_included_file_reaches_the_includers_nodes(tmp_path: Path) -> None:
    robot = '<robot name="bot"><link name="base"/></robot>'
    (tmp_path / "bot.urdf").write_text(robot)
    write(
        tmp_path,
        "inc/load_robot.launch",
        """
        <launch>
          <param name="robot_description" textfile="$(dirname)/../bot.urdf"/>
          <param name="rate_from_include" value="30"/>
        </launch>
        """,
    )
    path = write(
        tmp_path,
        "main.launch",
        """
        <launch>
          <group ns="robot1">
            <node pkg="mlaunch_demo" type="talker" name="before_include"/>
          </group>
          <include file="$(dirname)/inc/load_robot.launch"/>
          <node pkg="robot_state_publisher" type="robot_state_publisher" name="rsp"/>
        </launch>
        """,
    )
    plan = plan_of(path)
    nodes = {s.node.name: s for s in plan.processes() if s.node}
    assert globals_of(nodes["rsp"]) == {"rate_from_include": "30"}
    assert params(nodes["rsp"]) == {"robot_description": robot}
    # roslaunch sets every parameter before any node starts: the order of tags does not matter
    assert globals_of(nodes["before_include"]) == {"rate_from_include": "30"}
    assert "gets no robot_description" not in warnings_text(plan)


def test_find_xacro_as_an_argument_of_another_program_stays_its_path(tmp_path: Path) -> None:
    prefix = install_package(tmp_path / "install", "xacro", {"xacro": "#!/bin/sh\n"})
    path = write(
        tmp_path,
        "wrapped.launch",
        """
        <launch>
          <arg name="model" default="$(dirname)/robot.urdf.xacro"/>
          <node pkg="mlaunch_demo" type="talker" name="env_run"
                args="$(find xacro)/xacro $(arg model) --inorder"/>
        </launch>
        """,
    )
    ament = f"{prefix}{os.pathsep}{PREFIX}"
    (talker,) = plan_of(path, AMENT_PREFIX_PATH=ament).processes()
    assert list(talker.argv[1 : talker.argv.index("--ros-args")]) == [
        str(prefix / "lib" / "xacro" / "xacro"),
        str(tmp_path / "robot.urdf.xacro"),
        "--inorder",
    ]
    for fmt in ("py", "yaml", "xml"):  # a conversion names the same program
        out = converted(Path(path), fmt)
        ros2 = plan_of(str(out), AMENT_PREFIX_PATH=ament)
        assert summarize(ros2) == summarize(plan_of(path, AMENT_PREFIX_PATH=ament)), fmt
