"""The six causes of issue 24, each where mlaunch read a roslaunch file unlike roslaunch:
included ``*.launch.xml`` fragments, one unholdable value in a ``<rosparam>`` load, names that
point into another namespace, untyped substituted values, globals set in an included file,
and node ``args`` split before substitution."""

from __future__ import annotations

from pathlib import Path

from test_roslaunch import by_label, package, params, plan_of, warnings_text, write


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
