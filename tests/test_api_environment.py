"""The environment of a LaunchContext: a bare one works on ``os.environ`` itself, as launch's
does (scripts and unit tests of extensions read what their actions set there); a run's context
owns a copy and never touches the launcher's."""

from __future__ import annotations

import os
from collections.abc import Iterator

import pytest

from mlaunch import compat


@pytest.fixture(autouse=True)
def served() -> None:
    compat.install()


@pytest.fixture
def environ() -> Iterator[None]:
    """Give os.environ back exactly as it was, whatever a test's actions did to it."""
    saved = dict(os.environ)
    os.environ.pop("MLAUNCH_T_ENV", None)
    try:
        yield
    finally:
        os.environ.clear()
        os.environ.update(saved)


def test_a_bare_context_sets_and_unsets_in_os_environ(environ: None) -> None:
    from launch import LaunchContext
    from launch.actions import SetEnvironmentVariable, UnsetEnvironmentVariable

    context = LaunchContext()
    SetEnvironmentVariable("MLAUNCH_T_ENV", "one").visit(context)
    assert os.environ["MLAUNCH_T_ENV"] == "one"
    assert context.environment["MLAUNCH_T_ENV"] == "one"
    os.environ["MLAUNCH_T_ENV"] = "two"  # and what the script sets, the context sees
    assert context.environment["MLAUNCH_T_ENV"] == "two"
    UnsetEnvironmentVariable("MLAUNCH_T_ENV").visit(context)
    assert "MLAUNCH_T_ENV" not in os.environ


def test_push_and_pop_restore_os_environ_in_place(environ: None) -> None:
    from launch import LaunchContext
    from launch.actions import PopEnvironment, PushEnvironment, SetEnvironmentVariable

    context = LaunchContext()
    before = dict(os.environ)
    PushEnvironment().visit(context)
    SetEnvironmentVariable("MLAUNCH_T_ENV", "inside").visit(context)
    os.environ["PATH"] = "/nowhere"
    PopEnvironment().visit(context)
    assert dict(os.environ) == before
    assert context.environment is os.environ  # restored in place, not replaced


def test_pop_launch_configurations_keeps_os_environ(environ: None) -> None:
    from launch import LaunchContext
    from launch.actions import (
        PopLaunchConfigurations,
        PushLaunchConfigurations,
        SetEnvironmentVariable,
        SetLaunchConfiguration,
    )

    context = LaunchContext()
    PushLaunchConfigurations().visit(context)
    SetLaunchConfiguration("c", "v").visit(context)
    SetEnvironmentVariable("MLAUNCH_T_ENV", "kept").visit(context)
    PopLaunchConfigurations().visit(context)
    assert "c" not in context.launch_configurations
    assert os.environ["MLAUNCH_T_ENV"] == "kept"


def test_ros_log_dir_is_set_in_os_environ(environ: None, tmp_path) -> None:  # type: ignore[no-untyped-def]
    from launch import LaunchContext
    from launch.actions import PopEnvironment, PushEnvironment
    from launch_ros.actions import SetROSLogDir

    context = LaunchContext()
    PushEnvironment().visit(context)
    os.environ["ROS_LOG_DIR"] = str(tmp_path / "logs")
    SetROSLogDir("relative").visit(context)
    assert os.environ["ROS_LOG_DIR"] == str(tmp_path / "logs" / "relative")
    SetROSLogDir(str(tmp_path / "elsewhere")).visit(context)
    assert os.environ["ROS_LOG_DIR"] == str(tmp_path / "elsewhere")
    PopEnvironment().visit(context)
    assert os.environ.get("ROS_LOG_DIR") != str(tmp_path / "elsewhere")


def test_a_context_given_an_environment_never_touches_os_environ(environ: None) -> None:
    from launch import LaunchContext
    from launch.actions import PopEnvironment, PushEnvironment, SetEnvironmentVariable

    context = LaunchContext(environment={"PATH": "/bin"})
    PushEnvironment().visit(context)
    SetEnvironmentVariable("MLAUNCH_T_ENV", "copy").visit(context)
    assert context.environment["MLAUNCH_T_ENV"] == "copy"
    assert "MLAUNCH_T_ENV" not in os.environ
    PopEnvironment().visit(context)
    assert dict(context.environment) == {"PATH": "/bin"}
    assert "MLAUNCH_T_ENV" not in os.environ
