"""Pure tests of resolving descriptions: scoping, includes, arguments, env, triggers, errors."""

from __future__ import annotations

import os
import textwrap
from pathlib import Path

import pytest

from mlaunch import readers
from mlaunch.launch.actions import (
    AppendEnvironmentVariable,
    DeclareLaunchArgument,
    ExecuteProcess,
    GroupAction,
    IncludeLaunchDescription,
    LaunchDescription,
    LogInfo,
    OpaqueFunction,
    RegisterEventHandler,
    SetEnvironmentVariable,
    SetLaunchConfiguration,
    Shutdown,
    TimerAction,
    UnsetEnvironmentVariable,
)
from mlaunch.launch.conditions import IfCondition, UnlessCondition
from mlaunch.launch.event_handlers import OnProcessExit
from mlaunch.launch.launch_description_sources import PythonLaunchDescriptionSource
from mlaunch.launch.substitutions import EnvironmentVariable, LaunchConfiguration
from mlaunch.plan.errors import (
    LaunchArgumentError,
    LaunchFileError,
    MlaunchError,
    SubstitutionFailure,
)
from mlaunch.plan.pragmas import PRAGMA
from mlaunch.plan.steps import AddHandler, Log, Plan, StartTimer
from mlaunch.resolve.resolver import (
    LabelCounter,
    ResolveOptions,
    collect_arguments,
    resolve,
    resolve_deferred,
)

ENV = {"PATH": os.environ["PATH"], "HOME": "/home/u"}


def run(ld: LaunchDescription, path: str | None = None, **args: str) -> Plan:
    return resolve(ld, path=path, arguments=args, environ=ENV, options=ResolveOptions())


def logs(plan: Plan) -> list[str]:
    return [s.message for s in plan.steps if isinstance(s, Log)]


def test_group_is_scoped_and_forwarding_by_default() -> None:
    plan = run(
        LaunchDescription(
            [
                SetLaunchConfiguration("outer", "o"),
                GroupAction(
                    [
                        SetLaunchConfiguration("inner", "i"),
                        LogInfo(msg=[LaunchConfiguration("outer"), LaunchConfiguration("inner")]),
                    ]
                ),
                LogInfo(msg=LaunchConfiguration("inner", default="gone")),
            ]
        )
    )
    assert logs(plan) == ["oi", "gone"]


def test_group_not_forwarding_and_not_scoped() -> None:
    plan = run(
        LaunchDescription(
            [
                SetLaunchConfiguration("outer", "o"),
                GroupAction(
                    [LogInfo(msg=LaunchConfiguration("outer", default="hidden"))],
                    forwarding=False,
                    launch_configurations={"given": "g"},
                ),
                GroupAction([SetLaunchConfiguration("leak", "yes")], scoped=False),
                LogInfo(msg=LaunchConfiguration("leak")),
            ]
        )
    )
    assert logs(plan) == ["hidden", "yes"]


def test_group_scopes_environment_changes() -> None:
    plan = run(
        LaunchDescription(
            [
                GroupAction(
                    [
                        SetEnvironmentVariable("INSIDE", "1"),
                        ExecuteProcess(cmd=["true"], name="in"),
                    ]
                ),
                ExecuteProcess(cmd=["true"], name="out"),
            ]
        )
    )
    inside, outside = plan.processes()
    assert inside.env["INSIDE"] == "1" and inside.env_changes["INSIDE"] == "1"
    assert "INSIDE" not in outside.env


def test_arguments_defaults_override_choices_and_required() -> None:
    ld = LaunchDescription(
        [
            DeclareLaunchArgument("a", default_value="1"),
            DeclareLaunchArgument("m", default_value="x", choices=["x", "y"]),
            LogInfo(msg=[LaunchConfiguration("a"), LaunchConfiguration("m")]),
        ]
    )
    assert logs(run(ld)) == ["1x"]
    assert logs(run(ld, a="2", m="y")) == ["2y"]
    with pytest.raises(LaunchArgumentError, match="'z', which is not one of its choices: x, y"):
        run(ld, m="z")
    required = LaunchDescription([DeclareLaunchArgument("must")])
    with pytest.raises(LaunchArgumentError, match="Required launch argument 'must'") as err:
        run(required)
    assert err.value.where and err.value.where.endswith(".py:" + err.value.where.split(":")[-1])


def test_undeclared_argument_warns_with_did_you_mean() -> None:
    plan = run(
        LaunchDescription([DeclareLaunchArgument("use_sim_time", default_value="1")]),
        use_sim_tme="0",
    )
    assert plan.warnings == [
        "argument 'use_sim_tme' is not declared by the launch file (did you mean 'use_sim_time'?)"
    ]


def test_conditions_skip_actions() -> None:
    plan = run(
        LaunchDescription(
            [
                DeclareLaunchArgument("gui", default_value="false"),
                LogInfo(msg="shown", condition=UnlessCondition(LaunchConfiguration("gui"))),
                LogInfo(msg="hidden", condition=IfCondition(LaunchConfiguration("gui"))),
            ]
        )
    )
    assert logs(plan) == ["shown"]


def test_environment_actions_affect_later_processes_only() -> None:
    plan = run(
        LaunchDescription(
            [
                ExecuteProcess(cmd=["true"], name="before"),
                SetEnvironmentVariable("A", "1"),
                AppendEnvironmentVariable("A", "2"),
                AppendEnvironmentVariable("A", "0", prepend=True),
                UnsetEnvironmentVariable("HOME"),
                ExecuteProcess(cmd=["true"], name="after", additional_env={"B": "b"}),
                ExecuteProcess(cmd=["true"], name="clean", env={"ONLY": "x"}),
                LogInfo(msg=EnvironmentVariable("A")),
            ]
        )
    )
    before, after, clean = plan.processes()
    assert "A" not in before.env
    assert after.env["A"] == os.pathsep.join(["0", "1", "2"]) and after.env["B"] == "b"
    assert "HOME" not in after.env and after.env_changes["HOME"] is None
    assert set(clean.env) == {"ONLY", "PYTHONUNBUFFERED", "RCUTILS_LOGGING_BUFFERED_STREAM"}
    # mlaunch never touches its own environment for these.
    assert "A" not in os.environ or os.environ["A"] != logs(plan)[0]


def test_labels_count_globally_and_processes_get_line_buffering() -> None:
    plan = run(
        LaunchDescription(
            [
                ExecuteProcess(cmd=["true"]),
                ExecuteProcess(cmd=["/bin/echo", "x"], name="talker"),
                ExecuteProcess(cmd=["true"]),
            ]
        )
    )
    assert [p.label for p in plan.processes()] == ["true-1", "talker-2", "true-3"]
    spec = plan.processes()[1]
    assert spec.argv == ("/bin/echo", "x")
    assert spec.env["PYTHONUNBUFFERED"] == "1"
    assert spec.env["RCUTILS_LOGGING_BUFFERED_STREAM"] == "1"


def test_process_settings() -> None:
    plan = run(
        LaunchDescription(
            [
                SetLaunchConfiguration("sigterm_timeout", "2"),
                ExecuteProcess(
                    cmd=["true"],
                    output="screen",
                    respawn="on-failure",
                    respawn_delay=1.5,
                    respawn_max_retries=3,
                    on_exit=Shutdown(),
                    cwd="/tmp",
                    prefix="nice -n 5",
                ),
            ]
        )
    )
    (spec,) = plan.processes()
    assert spec.argv == ("nice", "-n", "5", "true") and spec.label == "nice-1"
    assert spec.sigterm_timeout == 2.0 and spec.sigkill_timeout == 5.0
    assert spec.respawn.mode == "on-failure" and spec.respawn.delay == 1.5
    assert spec.respawn.max_retries == 3
    assert spec.required and spec.cwd == "/tmp" and spec.output == "screen"


def test_bad_process_settings_are_located_errors() -> None:
    with pytest.raises(MlaunchError, match="output is 'loud'; valid: log, screen") as err:
        run(LaunchDescription([ExecuteProcess(cmd=["true"], output="loud")]))
    assert err.value.where and "test_resolve.py" in err.value.where
    with pytest.raises(MlaunchError, match="'no-such-program-xyz' not found on the PATH"):
        run(LaunchDescription([ExecuteProcess(cmd=["no-such-program-xyz"])]))
    with pytest.raises(MlaunchError, match="respawn is 'sometimes'"):
        run(LaunchDescription([ExecuteProcess(cmd=["true"], respawn="sometimes")]))
    with pytest.raises(MlaunchError, match="working directory '/no/such/dir'"):
        run(LaunchDescription([ExecuteProcess(cmd=["true"], cwd="/no/such/dir")]))


def test_substitution_failure_names_the_action() -> None:
    with pytest.raises(SubstitutionFailure) as err:
        run(LaunchDescription([ExecuteProcess(cmd=["echo", LaunchConfiguration("missing")])]))
    assert "launch configuration 'missing' does not exist" in str(err.value)
    assert err.value.what is not None and err.value.what.startswith("ExecuteProcess(")


def test_opaque_function_reads_context_and_returns_actions() -> None:
    def body(context, suffix):  # type: ignore[no-untyped-def]
        robot = context.launch_configurations["robot"]
        value = context.perform_substitution(LaunchConfiguration("robot"))
        return [LogInfo(msg=robot + value + suffix)]

    plan = run(
        LaunchDescription(
            [
                DeclareLaunchArgument("robot", default_value="r"),
                OpaqueFunction(function=body, args=["!"]),
            ]
        )
    )
    assert logs(plan) == ["rr!"]


def test_opaque_function_exception_is_located() -> None:
    def broken(context):  # type: ignore[no-untyped-def]
        nothing: dict[str, str] = {}
        return nothing["nope"]

    with pytest.raises(MlaunchError, match="KeyError") as err:
        run(LaunchDescription([OpaqueFunction(function=broken)]))
    assert err.value.where and "test_resolve.py" in err.value.where


def _timer_and_handler(capture: bool) -> tuple[StartTimer, AddHandler, Plan]:
    proc = ExecuteProcess(cmd=["true"])
    description = LaunchDescription(
        [
            SetLaunchConfiguration("v", "early"),
            TimerAction(period=1.5, actions=[LogInfo(msg=LaunchConfiguration("v"))]),
            RegisterEventHandler(OnProcessExit(target_action=proc, on_exit=[LogInfo(msg="x")])),
            SetLaunchConfiguration("v", "late"),
            proc,
        ]
    )
    options = ResolveOptions(capture=capture)
    plan = resolve(description, path=None, arguments={}, environ=ENV, options=options)
    timer = next(s for s in plan.steps if isinstance(s, StartTimer))
    handler = next(s for s in plan.steps if isinstance(s, AddHandler))
    return timer, handler, plan


def test_timers_and_handlers_resolve_when_they_fire_as_launch_does() -> None:
    timer, handler, plan = _timer_and_handler(capture=False)
    assert timer.period == 1.5 and timer.body is not None
    fired = resolve_deferred(timer.body, labels=LabelCounter(), options=ResolveOptions())
    (log,) = fired.steps
    assert isinstance(log, Log) and log.message == "late"  # ros2 launch's late binding
    (warning,) = fired.warnings
    assert "launch configuration 'v' is 'early' where written, 'late' when it fires" in warning
    assert handler.kind == "process_exit" and handler.matcher is not None
    assert handler.matcher(plan.processes()[0])


def test_capture_at_definition_keeps_the_values_where_written() -> None:
    timer, _, _ = _timer_and_handler(capture=True)
    assert timer.body is not None
    # The opt-in fix of ROS 2's L#501: the value where the timer was written.
    fired = resolve_deferred(timer.body, labels=LabelCounter(), options=ResolveOptions())
    (log,) = fired.steps
    assert isinstance(log, Log) and log.message == "early" and not fired.warnings


def test_a_comment_in_the_file_asks_for_capture(tmp_path: Path) -> None:
    path = write(
        tmp_path,
        "c.launch.yaml",
        f"# {PRAGMA}\n"
        """\
        launch:
        - let: {name: v, value: early}
        - timer: {period: 1.0, children: [{log: {message: $(var v)}}]}
        - let: {name: v, value: late}
        """,
    )
    plan = resolve(readers.load(path), path=path, arguments={}, environ={})
    (timer,) = [s for s in plan.steps if isinstance(s, StartTimer)]
    assert timer.body is not None
    fired = resolve_deferred(timer.body, labels=LabelCounter(), options=ResolveOptions())
    (log,) = fired.steps
    assert isinstance(log, Log) and log.message == "early"


def write(tmp: Path, name: str, text: str) -> str:
    path = tmp / name
    path.write_text(textwrap.dedent(text))
    return str(path)


def test_python_include_with_arguments_is_not_scoped(tmp_path: Path) -> None:
    child = write(
        tmp_path,
        "child.launch.py",
        """
        from launch import LaunchDescription
        from launch.actions import DeclareLaunchArgument, LogInfo, SetLaunchConfiguration
        from launch.substitutions import LaunchConfiguration, ThisLaunchFile

        def generate_launch_description():
            return LaunchDescription([
                DeclareLaunchArgument('who', default_value='nobody'),
                SetLaunchConfiguration('from_child', 'leaked'),
                LogInfo(msg=[LaunchConfiguration('who'), ' ', ThisLaunchFile()]),
            ])
        """,
    )
    parent = LaunchDescription(
        [
            IncludeLaunchDescription(
                PythonLaunchDescriptionSource(child), launch_arguments={"who": "me"}.items()
            ),
            LogInfo(msg=LaunchConfiguration("from_child")),
        ]
    )
    assert logs(run(parent, path=str(tmp_path / "parent.launch.py"))) == [f"me {child}", "leaked"]


def test_include_of_missing_file_is_an_error(tmp_path: Path) -> None:
    ld = LaunchDescription([IncludeLaunchDescription(str(tmp_path / "gone.launch.py"))])
    with pytest.raises(LaunchFileError, match="gone.launch.py' does not exist"):
        run(ld)


def test_python_loader_errors_are_located(tmp_path: Path) -> None:
    bad = write(tmp_path, "bad.launch.py", "def generate_launch_description(:\n    pass\n")
    with pytest.raises(LaunchFileError, match="syntax error") as err:
        readers.load(bad)
    assert err.value.where == f"{bad}:1:33"
    raising = write(
        tmp_path,
        "raising.launch.py",
        """
        def helper():
            raise ValueError('wrong robot')

        def generate_launch_description():
            return helper()
        """,
    )
    with pytest.raises(LaunchFileError, match="ValueError in generate_launch_description") as err:
        readers.load(raising)
    assert err.value.where == f"{raising}:3"
    none = write(tmp_path, "none.launch.py", "x = 1\n")
    with pytest.raises(LaunchFileError, match="no generate_launch_description"):
        readers.load(none)
    wrong = write(tmp_path, "wrong.launch.py", "def generate_launch_description():\n    return 3\n")
    with pytest.raises(LaunchFileError, match="returned int"):
        readers.load(wrong)


def test_show_args_follows_includes_and_marks_conditional(tmp_path: Path) -> None:
    child = write(
        tmp_path,
        "child.launch.py",
        """
        from launch import LaunchDescription
        from launch.actions import DeclareLaunchArgument
        def generate_launch_description():
            return LaunchDescription([DeclareLaunchArgument('inner', default_value='i',
                                                            description='from the child')])
        """,
    )
    ld = LaunchDescription(
        [
            DeclareLaunchArgument("top", description="top level"),
            DeclareLaunchArgument("maybe", default_value="m", condition=IfCondition("false")),
            IncludeLaunchDescription(PythonLaunchDescriptionSource(child)),
        ]
    )
    infos = {i.name: i for i in collect_arguments(ld, path=None, arguments={}, environ=ENV)}
    assert set(infos) == {"top", "maybe", "inner"}
    assert infos["top"].default is None and infos["inner"].description == "from the child"
    assert infos["maybe"].conditional and not infos["top"].conditional
