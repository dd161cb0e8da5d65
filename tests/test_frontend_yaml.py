"""The YAML frontend: the launch_yaml schema, YAML typing, and every error with file:line:col."""

from __future__ import annotations

import os
import textwrap
from pathlib import Path
from typing import Any

import pytest

from mlaunch import readers
from mlaunch.launch import actions
from mlaunch.launch.conditions import IfCondition, UnlessCondition
from mlaunch.plan.errors import LaunchFileError
from mlaunch.plan.steps import Log, Plan, RequestShutdown, StartTimer
from mlaunch.resolve.resolver import ResolveOptions, resolve

ENV = {"PATH": os.environ["PATH"], "HOME": "/home/u", "KEEP": "k"}


def write(tmp_path: Path, body: str, name: str = "t.launch.yaml") -> Path:
    path = tmp_path / name
    path.write_text(textwrap.dedent(body).lstrip("\n"))
    return path


def load(tmp_path: Path, body: str) -> actions.LaunchDescription:
    return readers.load(str(write(tmp_path, body)))


def plan_of(tmp_path: Path, body: str, **args: str) -> Plan:
    path = write(tmp_path, body)
    return resolve(
        readers.load(str(path)),
        path=str(path),
        arguments=args,
        environ=ENV,
        options=ResolveOptions(),
    )


def error(tmp_path: Path, body: str) -> LaunchFileError:
    path = write(tmp_path, body)
    with pytest.raises(LaunchFileError) as caught:
        readers.load(str(path))
    return caught.value


def logs(plan: Plan) -> list[str]:
    return [s.message for s in plan.steps if isinstance(s, Log)]


# --- schema ----------------------------------------------------------------------------------


def test_children_as_a_list_or_a_children_key(tmp_path: Path) -> None:
    plan = plan_of(
        tmp_path,
        """
        launch:
        - group:
          - let: {name: a, value: "1"}
          - log: {message: "list $(var a)"}
        - group:
            scoped: false
            children:
            - let: {name: b, value: "2"}
        - log: {message: "b=$(var b) a=$(var a none)"}
        - timer:
            period: 1
            children:
            - log: {message: later}
        - reset_env:
        """,
    )
    assert logs(plan) == ["list 1", "b=2 a=none"]
    assert [type(s).__name__ for s in plan.steps][-1] == "StartTimer"


def test_arg_choice_forms_and_typing_of_text(tmp_path: Path) -> None:
    ld = load(
        tmp_path,
        """
        launch:
        - arg:
            name: mode
            default: sim
            choice: [{value: sim}, {value: real}]
        - arg: {name: level, default: 3, choices: [1, 2, 3]}
        - arg: {name: flag, default: true, description: "A flag"}
        - arg: {name: ratio, default: 0.50}
        """,
    )
    mode, level, flag, ratio = ld.entities
    assert mode.choices == ["sim", "real"]
    assert level.choices == ["1", "2", "3"] and level.default_value[0].text == "3"
    # a YAML bool is written as launch text: lowercase, as conditions and XML expect
    assert flag.default_value[0].text == "true" and flag.description == "A flag"
    assert ratio.default_value[0].text == "0.50"  # as written, like the XML attribute


def test_include_of_xml_from_yaml_with_args(tmp_path: Path) -> None:
    write(
        tmp_path,
        """
        <launch>
          <arg name="who"/>
          <log message="xml got $(var who)"/>
        </launch>
        """,
        "inner.launch.xml",
    )
    plan = plan_of(
        tmp_path,
        """
        launch:
        - include:
            file: $(dirname)/inner.launch.xml
            arg: [{name: who, value: yaml}]
            let: [{name: other, value: x}]
        - log: {message: "$(var other)"}
        """,
    )
    assert logs(plan) == ["xml got yaml", "x"]


def test_executable_with_native_yaml_types(tmp_path: Path) -> None:
    plan = plan_of(
        tmp_path,
        f"""
        launch:
        - executable:
            cmd: sh -c 'exit 0'
            cwd: {tmp_path}
            name: worker
            shell: false
            output: both
            respawn: true
            respawn_delay: 2
            respawn_max_retries: 4
            sigterm_timeout: 1.5
            sigkill_timeout: 3
            emulate_tty: false
            on_exit: shutdown
            env: [{{name: N, value: 7}}]
        - executable: {{cmd: "true", respawn: always, required: true}}
        """,
    )
    first, second = plan.processes()
    assert first.argv == ("sh", "-c", "exit 0") and first.label == "worker-1"
    assert first.output == "both" and first.cwd == str(tmp_path)
    assert first.respawn.mode == "always" and first.respawn.delay == 2.0
    assert first.respawn.max_retries == 4
    assert (first.sigterm_timeout, first.sigkill_timeout) == (1.5, 3.0)
    assert first.env_changes["N"] == "7" and first.required
    assert second.respawn.mode == "always" and second.required


def test_every_core_action_and_conditions(tmp_path: Path) -> None:
    body = """
        launch:
        - arg: {name: enabled, default: "true"}
        - set_env: {name: A, value: "1", if: $(var enabled)}
        - append_env: {name: P, value: x, prepend: true, separator: ";"}
        - unset_env: {name: KEEP, unless: $(var enabled)}
        - let: {name: kept, value: k}
        - let: {name: gone, value: g}
        - reset:
            keep: [{name: kept, value: $(var kept)}, {name: enabled, value: $(var enabled)}]
        - log: {message: "$(var kept) $(var gone unset)"}
        - executable: {cmd: "true"}
        - shutdown: {reason: bye, if: $(var enabled)}
        - timer: {period: 0.5, cancel_on_shutdown: false, children: [log: {message: t}]}
        """
    plan = plan_of(tmp_path, body)
    (spec,) = plan.processes()
    assert spec.env_changes["A"] == "1" and spec.env_changes["P"] == "x"
    assert "KEEP" not in spec.env_changes
    assert logs(plan) == ["k unset"]
    assert [s.reason for s in plan.steps if isinstance(s, RequestShutdown)] == ["bye"]
    timer = next(s for s in plan.steps if isinstance(s, StartTimer))
    assert timer.period == 0.5 and timer.cancel_on_shutdown is False
    plan = plan_of(tmp_path, body, enabled="false")
    (spec,) = plan.processes()
    assert "A" not in spec.env_changes and spec.env_changes["KEEP"] is None
    ld = load(tmp_path, body)
    assert isinstance(ld.entities[1].condition, IfCondition)
    assert isinstance(ld.entities[3].condition, UnlessCondition)
    assert sorted(ld.entities[6].launch_configurations) == ["enabled", "kept"]


def test_origins_are_the_tag_lines(tmp_path: Path) -> None:
    ld = load(
        tmp_path,
        """
        launch:

        - log: {message: a}
        - group:
          - executable:
              cmd: "true"
        """,
    )
    log, group = ld.entities
    assert log.origin == f"{tmp_path}/t.launch.yaml:3"
    assert group.actions[0].origin == f"{tmp_path}/t.launch.yaml:5"


def test_anchors_and_aliases_work(tmp_path: Path) -> None:
    plan = plan_of(
        tmp_path,
        """
        launch:
        - executable: &common {cmd: "true", output: screen}
        - executable: *common
        """,
    )
    assert [p.label for p in plan.processes()] == ["true-1", "true-2"]


# --- errors ----------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("body", "where", "message"),
    [
        ("", "", "the file is empty"),
        ("launch: []\nother: 1\n", "1:1", "the root must be a map with the single key 'launch'"),
        ("lunch: []\n", "1:1", "the root key must be 'launch', not 'lunch'"),
        ("launch:\n- log: {message: a}\n  exec: x\n", "2:3", "a map with keys 'log', 'exec'"),
        ("launch:\n- just text\n", "2:3", "each entity is a map with one key"),
        ("launch:\n- log: hello\n", "2:8", "expected a map of attributes or a list"),
        ("launch:\n- lgo: {message: a}\n", "2:3", "unknown tag 'lgo' (did you mean 'log'?)"),
        ("launch:\n- log: {message: a, level: info}\n", "2:28", "unknown attribute 'level'"),
        ("launch:\n- log: {msg: a}\n", "2:3", "missing required attribute 'message'"),
        ("launch:\n- log: {message: [a, b]}\n", "2:18", "'message' is a list, expected text"),
        ("launch:\n- log: {message: {a: 1}}\n", "2:18", "'message' is a map, expected text"),
        ("launch:\n- log: {message: }\n", "2:18", "'message' is empty (null)"),
        ("launch:\n- log: {message: a, message: b}\n", "2:21", "key 'message' is given twice"),
        ("launch:\n- log: {message: a, children: []}\n", "2:3", "log takes no child entities"),
        ("launch:\n- log:\n  - log: {message: a}\n", "2:3", "log takes no child entities"),
        ("launch:\n- log: {message: a\n", "3:1", "malformed YAML"),
        ("launch:\n\t- log: {}\n", "2:1", "malformed YAML"),
        (
            "launch:\n- executable: {cmd: x, shell: sure}\n",
            "2:31",
            "attribute 'shell' is 'sure', expected a boolean",
        ),
        (
            "launch:\n- executable: {cmd: x, respawn_max_retries: 1.5}\n",
            "2:45",
            "'respawn_max_retries' is '1.5', expected an integer",
        ),
        (
            "launch:\n- executable: {cmd: x, env: {A: 1}}\n",
            "2:29",
            "attribute 'env' must be a list of maps",
        ),
        (
            "launch:\n- executable:\n    cmd: x\n    env: [{name: A, val: 1}]\n",
            "4:11",
            "missing required attribute 'value' (found 'val': a typo?)",
        ),
        ("launch:\n- log: {message: a, if: 'on'}\n", "2:26", "if='on' is not a condition"),
        (
            "launch:\n- log: {message: a, if: $(var a), unless: $(var b)}\n",
            "2:43",
            "cannot both be given",
        ),
        ("launch:\n- arg: {name: on}\n", "2:15", "'on', which YAML reads as a boolean; quote it"),
        ("launch:\n- arg: {name: a, choices: []}\n", "2:27", "'choices' is an empty list"),
        ("launch:\n- param: {name: a, value: 1}\n", "2:3", "use set_parameter"),
    ],
)
def test_errors_are_located(tmp_path: Path, body: str, where: str, message: str) -> None:
    path = tmp_path / "t.launch.yaml"
    path.write_text(body)
    with pytest.raises(LaunchFileError) as caught:
        readers.load(str(path))
    err = caught.value
    assert message in err.message, err.message
    assert err.where == (f"{path}:{where}" if where else str(path))
    assert "\n" not in str(err)


def test_unknown_attribute_lists_valid_ones_and_the_tag(tmp_path: Path) -> None:
    err = error(tmp_path, "launch:\n- append_env: {name: A, value: b, prepnd: true}\n")
    assert err.what == "append_env"
    assert "unknown attribute 'prepnd' (did you mean 'prepend'?)" in err.message
    assert err.message.endswith("valid attributes: prepend, separator, name, value")


def test_a_yaml_file_without_nodes_does_not_import_the_ros_layer(tmp_path: Path) -> None:
    import subprocess
    import sys

    path = write(tmp_path, "launch:\n- log: {message: hi}\n- executable: {cmd: 'true'}\n")
    code = (
        "import sys; import mlaunch.readers;"
        f" mlaunch.readers.load({str(path)!r});"
        " print(sorted(m for m in sys.modules if m.startswith(('mlaunch.ros', 'rclpy'))))"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    ).stdout
    assert out.strip() == "[]"


# --- launch_ros tags -------------------------------------------------------------------------


@pytest.fixture
def ros_plan(tmp_path: Path) -> Any:
    """Resolve YAML text against a fake install prefix holding package 'demo' (talker)."""
    prefix = tmp_path / "prefix"
    index = prefix / "share" / "ament_index" / "resource_index" / "packages"
    index.mkdir(parents=True)
    (index / "demo").touch()
    lib = prefix / "lib" / "demo"
    lib.mkdir(parents=True)
    (lib / "talker").write_text("#!/bin/sh\n")
    (lib / "talker").chmod(0o755)
    temp = tmp_path / "run"
    temp.mkdir()

    def run(body: str, **args: str) -> Plan:
        path = write(tmp_path, body)
        env = {**ENV, "AMENT_PREFIX_PATH": str(prefix)}
        options = ResolveOptions(temp_dir=str(temp), standins=False)
        return resolve(
            readers.load(str(path)), path=str(path), arguments=args, environ=env, options=options
        )

    return run


def params_of(argv: tuple[str, ...]) -> list[str]:
    return [Path(argv[i + 1]).read_text() for i, a in enumerate(argv) if a == "--params-file"]


def test_node_params_keep_their_yaml_types(ros_plan: Any) -> None:
    plan = ros_plan(
        """
        launch:
        - push-ros-namespace: {namespace: team}
        - set_parameter: {name: level, value: 3}
        - set_parameter: {name: flag, value: true}
        - node:
            pkg: demo
            exec: talker
            name: t
            param:
            - {name: i, value: 10}
            - {name: s, value: "10"}
            - {name: forced, value: 10, type: str}
            - {name: l, value: [1, 2.5]}
            - {name: names, value: [a, "$(var who)"]}
            - name: nested
              param:
              - {name: deep, value: off}
            remap:
            - {from: a, to: b}
        """,
        who="me",
    )
    (spec,) = plan.processes()
    assert spec.argv[1:8] == (
        "--ros-args", "-r", "__node:=t", "-r", "__ns:=/team", "-p", "level:=3",
    )  # fmt: skip
    assert spec.argv[8:10] == ("-p", "flag:=True") and spec.argv[-2:] == ("-r", "a:=b")
    head = "/team/t:\n  ros__parameters:\n    "
    assert params_of(spec.argv) == [
        head + "i: 10\n",
        head + "s: '10'\n",  # YAML text stays text (observed in Jazzy: conformance typed_values)
        head + "forced: '10'\n",
        head + "l:\n    - 1.0\n    - 2.5\n",
        head + "names:\n    - a\n    - me\n",
        head + "nested.deep: false\n",
    ]


def test_lifecycle_node_in_yaml(ros_plan: Any) -> None:
    plan = ros_plan(
        "launch:\n- lifecycle_node: {pkg: demo, exec: talker, name: lc, namespace: ns}\n"
    )
    (spec,) = plan.processes()
    assert spec.node is not None and spec.node.lifecycle and not spec.node.autostart


@pytest.mark.parametrize(
    ("param", "where", "message"),
    [
        ("{name: p, value: {a: 1}}", "4:30", "a parameter value cannot be a map"),
        ("{name: p, value: }", "4:30", "the parameter value is empty (null)"),
        ("{name: p, value: [1, a]}", "4:30", "must hold one type, this one mixes int, str"),
        ("{name: p, value: [[1]]}", "4:30", "a list parameter holds plain values"),
        ("{name: p, value: abc, type: int}", "4:30", "parameter value 'abc' is not of type int"),
        ("{name: p, value: 1, type: list_of_int}", "4:30", "is not a list"),
        ("{name: p, from: x.yaml}", "4:20", "'from' and 'name' cannot both be given"),
        ("{value: 1}", "4:13", "a param needs 'name'"),
    ],
)
def test_param_errors(tmp_path: Path, param: str, where: str, message: str) -> None:
    body = f"launch:\n- node:\n    exec: x\n    param: [{param}]\n"
    err = error(tmp_path, body)
    assert message in err.message
    assert err.where == f"{tmp_path}/t.launch.yaml:{where}"
    assert err.what == "param"
