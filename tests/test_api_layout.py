"""launch's and launch_ros's module paths and helpers, as upstream lays them out (issue 25)."""

from __future__ import annotations

import importlib
import signal
import sys

import pytest

from mlaunch import compat


@pytest.fixture(autouse=True)
def served() -> None:
    compat.install()


@pytest.mark.parametrize(
    ("module", "name"),
    [
        ("launch.actions.execute_process", "ExecuteProcess"),
        ("launch.actions.emit_event", "EmitEvent"),
        ("launch.substitutions.substitution_failure", "SubstitutionFailure"),
        ("launch.event_handlers.on_process_start", "OnProcessStart"),
        ("launch.event_handlers.on_shutdown", "OnShutdown"),
        ("launch.events.process.process_stdin", "ProcessStdin"),
        ("launch.events.timer_event", "TimerEvent"),
        ("launch.conditions.invalid_condition_expression_error", "InvalidConditionExpressionError"),
        ("launch.utilities.signal_management", "AsyncSafeSignalManager"),
        ("launch.descriptions.executable", "Executable"),
        ("launch.invalid_launch_file_error", "InvalidLaunchFileError"),
        ("launch_ros.actions.node", "Node"),
        ("launch_ros.actions.load_composable_nodes", "LoadComposableNodes"),
        ("launch_ros.actions.composable_node_container", "ComposableNodeContainer"),
        ("launch_ros.actions.ros_timer", "ROSTimer"),
        ("launch_ros.actions.lifecycle_transition", "LifecycleTransition"),
        ("launch_ros.events.lifecycle.change_state", "ChangeState"),
        ("launch_ros.event_handlers.on_state_transition", "OnStateTransition"),
        ("launch_ros.utilities.track_node_names", "get_node_name_count"),
    ],
)
def test_upstream_submodules_import_with_their_names(module: str, name: str) -> None:
    loaded = importlib.import_module(module)
    assert getattr(loaded, name) is getattr(importlib.import_module(module.rsplit(".", 1)[0]), name)


def test_prefix_namespace_keeps_relative_results_relative() -> None:
    from launch_ros.utilities import prefix_namespace

    assert prefix_namespace("asd", None) == "asd"
    assert prefix_namespace(None, "x/") == "x"
    assert prefix_namespace("/a", "b") == "/a/b"
    assert prefix_namespace("a", "/b") == "/b"
    assert prefix_namespace("/", "b") == "/b"
    assert prefix_namespace(None, None) is None


def test_normalize_remap_rule_and_parameters_refuse_with_type_errors() -> None:
    from launch.substitutions import TextSubstitution
    from launch_ros.utilities import normalize_parameters, normalize_remap_rule

    src, dst = normalize_remap_rule(("a", "b"))
    assert [type(s) for s in (*src, *dst)] == [TextSubstitution, TextSubstitution]
    with pytest.raises(TypeError):
        normalize_remap_rule(("a", "b", "c"))
    with pytest.raises(TypeError):
        normalize_remap_rule(["a", "b"])
    with pytest.raises(TypeError):
        normalize_parameters("params.yaml")


def test_node_name_counts_are_shared_with_nodes() -> None:
    from launch import LaunchContext
    from launch_ros.utilities import add_node_name, get_node_name_count

    context = LaunchContext()
    assert get_node_name_count(context, "/n") == 0
    add_node_name(context, "/n")
    add_node_name(context, "/n")
    assert get_node_name_count(context, "/n") == 2


def test_ensure_argument_type_names_the_caller() -> None:
    from launch.utilities import ensure_argument_type

    ensure_argument_type(1, (str, int), "x")
    with pytest.raises(TypeError, match="'Mine' expected 'x' to be one of"):
        ensure_argument_type(1.5, [str, int], "x", "Mine")
    with pytest.raises(TypeError):
        ensure_argument_type(1, 5, "x")  # type: ignore[arg-type]


def test_invalid_launch_file_error_lists_what_each_loader_raised() -> None:
    from launch import InvalidLaunchFileError

    text = str(InvalidLaunchFileError(".py", likely_errors=[KeyError("k"), ValueError("v")]))
    assert "multiple exceptions" in text and "KeyError" in text and "ValueError" in text
    assert "syntax error" in str(InvalidLaunchFileError())


def test_python_loader_refuses_a_file_without_the_function(tmp_path) -> None:  # type: ignore[no-untyped-def]
    from launch.launch_description_sources import (
        InvalidPythonLaunchFileError,
        get_launch_description_from_python_launch_file,
    )

    empty = tmp_path / "empty.launch.py"
    empty.write_text("x = 1\n")
    with pytest.raises(InvalidPythonLaunchFileError, match="generate_launch_description"):
        get_launch_description_from_python_launch_file(str(empty))
    good = tmp_path / "good.launch.py"
    good.write_text(
        "from launch import LaunchDescription\n"
        "def generate_launch_description():\n    return LaunchDescription([])\n"
    )
    assert get_launch_description_from_python_launch_file(str(good)).entities == []


def test_condition_expressions_as_upstream() -> None:
    from launch import LaunchContext
    from launch.conditions import (
        InvalidConditionExpressionError,
        evaluate_condition_expression,
    )
    from launch.substitutions import TextSubstitution

    context = LaunchContext()
    assert evaluate_condition_expression(context, [TextSubstitution(text=" TRUE ")]) is True
    assert evaluate_condition_expression(context, [TextSubstitution(text="0")]) is False
    with pytest.raises(InvalidConditionExpressionError, match="got 'on'") as raised:
        evaluate_condition_expression(context, [TextSubstitution(text="on")])
    assert isinstance(raised.value, ValueError)


@pytest.mark.skipif(sys.platform != "linux", reason="signal wakeup fds as on Linux")
def test_async_safe_signal_manager_runs_handlers_on_the_loop() -> None:
    import asyncio
    import os

    from launch.utilities import AsyncSafeSignalManager

    loop = asyncio.new_event_loop()
    got: list[int] = []
    try:
        with AsyncSafeSignalManager(loop) as manager:
            manager.handle(signal.SIGUSR1, got.append)
            previous = signal.signal(signal.SIGUSR1, lambda *a: None)
            try:
                os.kill(os.getpid(), signal.SIGUSR1)
                loop.run_until_complete(_until(lambda: bool(got), loop))
            finally:
                signal.signal(signal.SIGUSR1, previous)
    finally:
        loop.close()
    assert got == [signal.SIGUSR1]


async def _until(done, loop) -> None:  # type: ignore[no-untyped-def]
    deadline = loop.time() + 5
    while not done():
        assert loop.time() < deadline, "the signal handler never ran"
        await __import__("asyncio").sleep(0.01)


def test_composable_node_load_request_as_launch_ros_builds_it() -> None:
    pytest.importorskip("composition_interfaces.srv")
    from launch import LaunchContext
    from launch_ros.actions.load_composable_nodes import get_composable_node_load_request
    from launch_ros.descriptions import ComposableNode

    context = LaunchContext()
    context.launch_configurations["ros_namespace"] = "/robot"
    request = get_composable_node_load_request(
        ComposableNode(package="p", plugin="a::B", name="n", parameters=[{"x": 1}]), context
    )
    assert (request.package_name, request.plugin_name, request.node_name) == ("p", "a::B", "n")
    assert request.node_namespace == "/robot"
    assert [(p.name, p.value.integer_value) for p in request.parameters] == [("x", 1)]


def test_bad_node_parameters_are_type_errors_as_upstream() -> None:
    from launch_ros.actions import Node

    for bad in ([5.0], {"a": 5}, "params.yaml"):
        with pytest.raises(TypeError, match="parameters"):
            Node(package="p", executable="e", parameters=bad)


def test_matches_node_name_takes_a_relative_name_from_the_root() -> None:
    from launch_ros.events import matches_node_name

    class Named:
        def __init__(self, node_name: str) -> None:
            self.node_name = node_name

    assert matches_node_name("foo")(Named("/foo"))
    assert not matches_node_name("foo")(Named("/foo/bar"))


def test_node_perform_substitutions_resolves_its_names_as_launch_ros() -> None:
    from launch import LaunchContext
    from launch_ros.actions import Node, PushROSNamespace

    context = LaunchContext()
    PushROSNamespace("ns1").execute(context)
    node = Node(package="p", executable="e", name="my_node")
    node._perform_substitutions(context)
    assert (node.node_name, node.expanded_node_namespace) == ("/ns1/my_node", "/ns1")
    unnamed = Node(package="p", executable="e")
    unnamed._perform_substitutions(LaunchContext())
    assert unnamed.node_name == f"{Node.UNSPECIFIED_NODE_NAMESPACE}/{Node.UNSPECIFIED_NODE_NAME}"
