"""Pure tests of substitutions and conditions: ROS 2 semantics, and errors that say what failed."""

from __future__ import annotations

import os
import sys

import pytest

from mlaunch.launch.conditions import (
    IfCondition,
    LaunchConfigurationEquals,
    LaunchConfigurationNotEquals,
    UnlessCondition,
)
from mlaunch.launch.launch_context import LaunchContext
from mlaunch.launch.substitutions import (
    AndSubstitution,
    AnonName,
    Command,
    EnvironmentVariable,
    EqualsSubstitution,
    FindExecutable,
    IfElseSubstitution,
    LaunchConfiguration,
    NotEqualsSubstitution,
    NotSubstitution,
    OrSubstitution,
    PathJoinSubstitution,
    PythonExpression,
    TextSubstitution,
    ThisLaunchFile,
    ThisLaunchFileDir,
    perform,
)
from mlaunch.plan.errors import InvalidConditionExpressionError, SubstitutionFailure


@pytest.fixture
def ctx() -> LaunchContext:
    c = LaunchContext(environment={"HOME": "/home/u", "PATH": os.environ.get("PATH", "")})
    c.launch_configurations.update({"robot": "rb1", "flag": "true", "n": "2"})
    return c


def test_lists_concatenate(ctx: LaunchContext) -> None:
    assert perform(ctx, ["a-", LaunchConfiguration("robot"), "-b"]) == "a-rb1-b"


def test_launch_configuration_default_and_missing(ctx: LaunchContext) -> None:
    assert perform(ctx, LaunchConfiguration("nope", default="dflt")) == "dflt"
    assert perform(ctx, LaunchConfiguration("nope", default=5)) == "5"
    assert perform(ctx, LaunchConfiguration(["ro", "bot"])) == "rb1"
    with pytest.raises(SubstitutionFailure, match="'nope' does not exist"):
        perform(ctx, LaunchConfiguration("nope"))


def test_environment_variable(ctx: LaunchContext) -> None:
    assert perform(ctx, EnvironmentVariable("HOME")) == "/home/u"
    assert perform(ctx, EnvironmentVariable("UNSET_X", default_value="d")) == "d"
    # ROS 2 raises for an unset variable without default (its docstring says otherwise).
    with pytest.raises(SubstitutionFailure, match="UNSET_X"):
        perform(ctx, EnvironmentVariable("UNSET_X"))


def test_path_join_and_operator(ctx: LaunchContext) -> None:
    joined = PathJoinSubstitution(["/opt", LaunchConfiguration("robot"), "urdf"]) / "x.xacro"
    assert perform(ctx, joined) == "/opt/rb1/urdf/x.xacro"


def test_python_expression_has_math_names(ctx: LaunchContext) -> None:
    assert perform(ctx, PythonExpression(["2 * ", LaunchConfiguration("n")])) == "4"
    assert perform(ctx, PythonExpression("floor(pi)")) == "3"
    with pytest.raises(SubstitutionFailure, match="ZeroDivisionError"):
        perform(ctx, PythonExpression("1/0"))


def test_command_output_and_failures(ctx: LaunchContext) -> None:
    assert perform(ctx, Command(["echo ", LaunchConfiguration("robot")])) == "rb1\n"
    with pytest.raises(SubstitutionFailure, match="exit status 3"):
        perform(ctx, Command(f"{sys.executable} -c 'import sys; sys.exit(3)'"))
    noisy = f"{sys.executable} -c 'import sys; sys.stderr.write(\"warn\"); print(1)'"
    with pytest.raises(SubstitutionFailure, match="wrote to stderr"):
        perform(ctx, Command(noisy))
    assert perform(ctx, Command(noisy, on_stderr="ignore")) == "1\n"
    assert perform(ctx, Command(noisy, on_stderr="capture")) == "1\nwarn"
    with pytest.raises(SubstitutionFailure, match="not found"):
        perform(ctx, Command("definitely-not-a-program-xyz"))


def test_find_executable(ctx: LaunchContext) -> None:
    assert perform(ctx, FindExecutable(name="sh")).endswith("/sh")
    with pytest.raises(SubstitutionFailure, match="not found on the PATH"):
        perform(ctx, FindExecutable(name="no-such-program-xyz"))


def test_this_launch_file(ctx: LaunchContext) -> None:
    with pytest.raises(SubstitutionFailure):
        perform(ctx, ThisLaunchFile())
    with ctx.file_locals("/a/b/c.launch.py"):
        assert perform(ctx, ThisLaunchFile()) == "/a/b/c.launch.py"
        assert perform(ctx, ThisLaunchFileDir()) == "/a/b"


def test_anon_name_is_cached_per_name(ctx: LaunchContext) -> None:
    first = perform(ctx, AnonName("talker"))
    assert first.startswith("talker_") and "-" not in first and "." not in first
    assert perform(ctx, AnonName("talker")) == first
    assert perform(ctx, AnonName("other")) != first


@pytest.mark.parametrize(
    ("left", "right", "equal"),
    [
        ("true", "True", True),
        ("1", "true", True),
        ("0", "false", True),
        ("1.0", "1", True),
        ("abc", "abc", True),
        ("abc", "abd", False),
        (None, "", True),
        (True, "true", True),
        ("2.5", "2.50000000001", True),
    ],
)
def test_equals_is_bool_and_float_aware(
    ctx: LaunchContext, left: object, right: object, equal: bool
) -> None:
    assert perform(ctx, EqualsSubstitution(left, right)) == ("true" if equal else "false")
    assert perform(ctx, NotEqualsSubstitution(left, right)) == ("false" if equal else "true")


def test_boolean_substitutions_take_yaml_bools(ctx: LaunchContext) -> None:
    assert perform(ctx, NotSubstitution("yes")) == "false"
    assert perform(ctx, AndSubstitution(LaunchConfiguration("flag"), "1")) == "true"
    assert perform(ctx, OrSubstitution("off", "0")) == "false"
    with pytest.raises(SubstitutionFailure, match="not a boolean"):
        perform(ctx, NotSubstitution("maybe"))


def test_if_else(ctx: LaunchContext) -> None:
    assert perform(ctx, IfElseSubstitution(LaunchConfiguration("flag"), "a", "b")) == "a"
    assert perform(ctx, IfElseSubstitution("false", "a", "b")) == "b"
    assert perform(ctx, IfElseSubstitution("false", if_value="a")) == ""
    with pytest.raises(RuntimeError, match="One of if_value and else_value"):
        IfElseSubstitution("true")  # launch raises RuntimeError, not TypeError


def test_conditions_are_strict(ctx: LaunchContext) -> None:
    assert IfCondition("true").evaluate(ctx)
    assert IfCondition(" 1 ").evaluate(ctx)
    assert not IfCondition("False").evaluate(ctx)
    assert UnlessCondition("0").evaluate(ctx)
    # Conditions accept only true/false/1/0, unlike the boolean substitutions.
    with pytest.raises(InvalidConditionExpressionError, match="'yes'"):
        IfCondition("yes").evaluate(ctx)


def test_launch_configuration_equals(ctx: LaunchContext) -> None:
    with pytest.warns(UserWarning, match="deprecated"):  # as launch warns
        assert LaunchConfigurationEquals("robot", "rb1").evaluate(ctx)
        assert LaunchConfigurationNotEquals("robot", "rb2").evaluate(ctx)
        assert LaunchConfigurationEquals("unset", None).evaluate(ctx)


def test_text_substitution_describe() -> None:
    assert TextSubstitution(text="x").describe() == "'x'"
    assert LaunchConfiguration("a").describe() == "LaunchConfig('a')"
