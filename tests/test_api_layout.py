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


# Where upstream (launch 3.4.3, launch_ros 0.26.6) defines each class: the module that defines
# it in mlaunch too (issue 31), so a new action is one module, as in ros2/launch.
DEFINED_WHERE_UPSTREAM = {
    "launch.action": ["Action"],
    "launch.condition": ["Condition"],
    "launch.event": ["Event"],
    "launch.event_handler": ["EventHandler"],
    "launch.launch_description": ["LaunchDescription"],
    "launch.launch_description_entity": ["LaunchDescriptionEntity"],
    "launch.launch_description_source": ["LaunchDescriptionSource"],
    "launch.actions.append_environment_variable": ["AppendEnvironmentVariable"],
    "launch.actions.declare_launch_argument": ["DeclareLaunchArgument"],
    "launch.actions.emit_event": ["EmitEvent"],
    "launch.actions.execute_local": ["ExecuteLocal"],
    "launch.actions.execute_process": ["ExecuteProcess"],
    "launch.actions.group_action": ["GroupAction"],
    "launch.actions.include_launch_description": ["IncludeLaunchDescription"],
    "launch.actions.log_info": ["LogInfo"],
    "launch.actions.opaque_coroutine": ["OpaqueCoroutine"],
    "launch.actions.opaque_function": ["OpaqueFunction"],
    "launch.actions.pop_environment": ["PopEnvironment"],
    "launch.actions.pop_launch_configurations": ["PopLaunchConfigurations"],
    "launch.actions.push_environment": ["PushEnvironment"],
    "launch.actions.push_launch_configurations": ["PushLaunchConfigurations"],
    "launch.actions.register_event_handler": ["RegisterEventHandler"],
    "launch.actions.reset_environment": ["ResetEnvironment"],
    "launch.actions.reset_launch_configurations": ["ResetLaunchConfigurations"],
    "launch.actions.set_environment_variable": ["SetEnvironmentVariable"],
    "launch.actions.set_launch_configuration": ["SetLaunchConfiguration"],
    "launch.actions.shutdown_action": ["Shutdown"],
    "launch.actions.timer_action": ["TimerAction"],
    "launch.actions.unregister_event_handler": ["UnregisterEventHandler"],
    "launch.actions.unset_environment_variable": ["UnsetEnvironmentVariable"],
    "launch.actions.unset_launch_configuration": ["UnsetLaunchConfiguration"],
    "launch.conditions.if_condition": ["IfCondition"],
    "launch.conditions.unless_condition": ["UnlessCondition"],
    "launch.conditions.launch_configuration_equals": ["LaunchConfigurationEquals"],
    "launch.conditions.launch_configuration_not_equals": ["LaunchConfigurationNotEquals"],
    "launch.conditions.invalid_condition_expression_error": ["InvalidConditionExpressionError"],
    "launch.conditions.evaluate_condition_expression_impl": ["evaluate_condition_expression"],
    "launch.event_handlers.event_named": ["event_named"],
    "launch.event_handlers.on_execution_complete": ["OnExecutionComplete"],
    "launch.event_handlers.on_include_launch_description": ["OnIncludeLaunchDescription"],
    "launch.event_handlers.on_process_exit": ["OnProcessExit"],
    "launch.event_handlers.on_process_io": ["OnProcessIO"],
    "launch.event_handlers.on_process_start": ["OnProcessStart"],
    "launch.event_handlers.on_shutdown": ["OnShutdown"],
    "launch.events.execution_complete": ["ExecutionComplete"],
    "launch.events.include_launch_description": ["IncludeLaunchDescription"],
    "launch.events.matchers": ["matches_action"],
    "launch.events.shutdown": ["Shutdown"],
    "launch.events.timer_event": ["TimerEvent"],
    "launch.events.process.process_exited": ["ProcessExited"],
    "launch.events.process.process_io": ["ProcessIO"],
    "launch.events.process.process_started": ["ProcessStarted"],
    "launch.events.process.process_stderr": ["ProcessStderr"],
    "launch.events.process.process_stdin": ["ProcessStdin"],
    "launch.events.process.process_stdout": ["ProcessStdout"],
    "launch.events.process.process_targeted_event": ["ProcessTargetedEvent"],
    "launch.events.process.running_process_event": ["RunningProcessEvent"],
    "launch.events.process.shutdown_process": ["ShutdownProcess"],
    "launch.events.process.signal_process": ["SignalProcess"],
    "launch.events.process.process_matchers": ["matches_pid", "matches_name", "matches_executable"],
    "launch.launch_description_sources.any_launch_description_source": [
        "AnyLaunchDescriptionSource"
    ],
    "launch.launch_description_sources.frontend_launch_description_source": [
        "FrontendLaunchDescriptionSource"
    ],
    "launch.launch_description_sources.python_launch_description_source": [
        "PythonLaunchDescriptionSource"
    ],
    "launch.substitutions.anon_name": ["AnonName"],
    "launch.substitutions.boolean_substitution": [
        "NotSubstitution",
        "AndSubstitution",
        "OrSubstitution",
        "AnySubstitution",
        "AllSubstitution",
    ],
    "launch.substitutions.command": ["Command"],
    "launch.substitutions.environment_variable": ["EnvironmentVariable"],
    "launch.substitutions.equals_substitution": ["EqualsSubstitution"],
    "launch.substitutions.file_content": ["FileContent"],
    "launch.substitutions.find_executable": ["FindExecutable"],
    "launch.substitutions.if_else_substitution": ["IfElseSubstitution"],
    "launch.substitutions.launch_configuration": ["LaunchConfiguration"],
    "launch.substitutions.launch_log_dir": ["LaunchLogDir"],
    "launch.substitutions.local_substitution": ["LocalSubstitution"],
    "launch.substitutions.not_equals_substitution": ["NotEqualsSubstitution"],
    "launch.substitutions.path_join_substitution": ["PathJoinSubstitution"],
    "launch.substitutions.python_expression": ["PythonExpression"],
    "launch.substitutions.this_launch_file": ["ThisLaunchFile"],
    "launch.substitutions.this_launch_file_dir": ["ThisLaunchFileDir"],
    "launch_ros.actions.composable_node_container": ["ComposableNodeContainer"],
    "launch_ros.actions.lifecycle_node": ["LifecycleNode"],
    "launch_ros.actions.lifecycle_transition": ["LifecycleTransition"],
    "launch_ros.actions.load_composable_nodes": ["LoadComposableNodes"],
    "launch_ros.actions.node": ["Node"],
    "launch_ros.actions.push_ros_namespace": ["PushROSNamespace"],
    "launch_ros.actions.ros_timer": ["ROSTimer"],
    "launch_ros.actions.set_parameter": ["SetParameter"],
    "launch_ros.actions.set_parameters_from_file": ["SetParametersFromFile"],
    "launch_ros.actions.set_remap": ["SetRemap"],
    "launch_ros.actions.set_ros_log_dir": ["SetROSLogDir"],
    "launch_ros.actions.set_use_sim_time": ["SetUseSimTime"],
    "launch_ros.descriptions.composable_node": ["ComposableNode"],
    "launch_ros.event_handlers.on_state_transition": ["OnStateTransition"],
    "launch_ros.events.lifecycle.change_state": ["ChangeState"],
    "launch_ros.events.lifecycle.state_transition": ["StateTransition"],
    "launch_ros.substitutions.executable_in_package": ["ExecutableInPackage"],
    "launch_ros.substitutions.find_package": [
        "FindPackage",
        "FindPackagePrefix",
        "FindPackageShare",
    ],
    "launch_ros.substitutions.parameter": ["Parameter"],
}


@pytest.mark.parametrize("module", sorted(DEFINED_WHERE_UPSTREAM))
def test_each_name_is_defined_in_the_module_upstream_defines_it_in(module: str) -> None:
    loaded = importlib.import_module(module)
    for name in DEFINED_WHERE_UPSTREAM[module]:
        assert getattr(loaded, name).__module__ == f"mlaunch.{module}", (module, name)


GATHERING_PACKAGES = [
    "launch.actions",
    "launch.conditions",
    "launch.events",
    "launch.events.process",
    "launch.event_handlers",
    "launch.launch_description_sources",
    "launch.substitutions",
    "launch_ros.actions",
    "launch_ros.descriptions",
    "launch_ros.event_handlers",
    "launch_ros.events",
    "launch_ros.events.lifecycle",
    "launch_ros.substitutions",
]


@pytest.mark.parametrize("package", GATHERING_PACKAGES)
def test_a_package_only_gathers_the_names_of_its_modules(package: str) -> None:
    import ast
    import inspect

    loaded = importlib.import_module(package)
    tree = ast.parse(inspect.getsource(loaded))
    defined = [
        node.name
        for node in tree.body
        if isinstance(node, (ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef))
    ]
    assert defined == [], f"{package} defines {defined}: each belongs in a module of its own"
    for name in loaded.__all__:
        assert getattr(loaded, name) is not None  # each gathered name loads
    assert set(loaded.__all__) <= set(dir(loaded))


def test_every_name_a_launch_package_lists_resolves() -> None:
    """Each package of the launch API serves every name of its ``__all__`` or ``__dir__`` (a name
    left pointing at the module it moved out of fails here, not in a user's launch file)."""
    import importlib
    import pkgutil

    import mlaunch.launch
    import mlaunch.launch_ros

    missing = []
    for root in (mlaunch.launch, mlaunch.launch_ros):
        packages = [root.__name__] + [
            m.name for m in pkgutil.walk_packages(root.__path__, root.__name__ + ".") if m.ispkg
        ]
        for name in packages:
            module = importlib.import_module(name)
            for attribute in getattr(module, "__all__", None) or dir(module):
                if attribute in ("LaunchService", "SomeActionsType"):
                    continue  # served by mlaunch.compat (launch.provide) once a run's API is up
                try:
                    getattr(module, attribute)
                except AttributeError as e:
                    missing.append(f"{name}.{attribute}: {e}")
    assert missing == []
