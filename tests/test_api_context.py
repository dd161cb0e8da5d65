"""LaunchContext, handlers, events and descriptions as actions written against upstream use
them (issue 25: gaps 1, 6, 7, 8, 12)."""

from __future__ import annotations

from pathlib import Path

import pytest

from mlaunch import compat
from mlaunch.plan.steps import AddHandler, EmitEvent, RemoveHandler, RequestShutdown


@pytest.fixture(autouse=True)
def served() -> None:
    compat.install()


def test_a_bare_context_takes_argv_and_noninteractive() -> None:
    from launch import LaunchContext

    assert LaunchContext().argv == [] and not LaunchContext().noninteractive
    context = LaunchContext(argv=["a", "b"], noninteractive=True)
    assert context.argv == ["a", "b"] and context.noninteractive
    assert context.asyncio_loop is None


def test_locals_are_read_only_and_scoped() -> None:
    from launch import LaunchContext

    context = LaunchContext()
    context.extend_locals({"foo": 1})
    with pytest.raises(AttributeError):
        context.locals.foo = 2
    context._push_locals()
    context.extend_locals({"foo": 2, "bar": 3})
    context._pop_locals()
    assert context.locals.foo == 1 and "bar" not in context.locals
    with pytest.raises(RuntimeError):
        context._pop_locals()


def test_handlers_registered_through_the_context_become_plan_steps() -> None:
    from launch import LaunchContext
    from launch.actions import LogInfo
    from launch.event_handlers import OnProcessExit

    context = LaunchContext()
    handler = OnProcessExit(on_exit=[LogInfo(msg="gone")])
    context.register_event_handler(handler)
    context.unregister_event_handler(handler)
    with pytest.raises(ValueError):
        context.unregister_event_handler(handler)
    steps = context.planner.plan.steps
    assert [type(s) for s in steps] == [AddHandler, RemoveHandler]
    assert steps[0].kind == "process_exit" and steps[1].handler is handler


def test_emitted_events_become_plan_steps() -> None:
    from launch import LaunchContext
    from launch.events import Shutdown
    from launch.events.process import ShutdownProcess

    context = LaunchContext()
    context.emit_event_sync(ShutdownProcess(process_matcher=lambda p: True))
    context.emit_event_sync(Shutdown(reason="done"))
    first, second = context.planner.plan.steps
    assert isinstance(first, EmitEvent) and isinstance(first.event, ShutdownProcess)
    assert isinstance(second, RequestShutdown) and second.reason == "done"


def test_event_handler_matches_and_handles_as_upstream() -> None:
    from launch import EventHandler, LaunchContext, LaunchDescriptionEntity
    from launch.event_handlers import OnProcessStart
    from launch.events.process import ProcessStarted

    entity = LaunchDescriptionEntity()
    handler = EventHandler(matcher=lambda event: True, entities=[entity], handle_once=True)
    context = LaunchContext()
    context.register_event_handler(handler)
    event = object()
    assert handler.matches(event)
    assert handler.handle(event, context) == [entity]
    assert context.locals.event is event
    with pytest.raises(ValueError):  # handled once: it unregistered itself
        handler.handle(event, context)

    from launch.actions import ExecuteProcess

    target = ExecuteProcess(cmd=["true"])
    on_start = OnProcessStart(target_action=target, on_start=[])
    assert on_start.matches(ProcessStarted(action=target))
    assert not on_start.matches(ProcessStarted(action=object()))
    text, entities = on_start.describe()
    assert text.startswith("OnProcessStart(") and entities == []


def test_event_names_and_bare_condition_as_upstream() -> None:
    from launch import Condition, Event, LaunchContext
    from launch.events import ExecutionComplete, TimerEvent

    assert Event().name == "launch.Event"
    assert TimerEvent(timer_action=None).name == "launch.events.TimerEvent"
    assert ExecutionComplete(action=None).name == "launch.events.ExecutionComplete"
    assert Condition().evaluate(LaunchContext()) is False
    assert Condition(predicate=lambda context: True).evaluate(LaunchContext()) is True


def test_executable_prepares_its_final_values() -> None:
    from launch import LaunchContext
    from launch.descriptions import Executable
    from launch.substitutions import EnvironmentVariable

    context = LaunchContext(environment={"WHERE": "here", "PATH": "/bin"})
    context.launch_configurations["launch-prefix"] = "nice -n 5"
    exe = Executable(cmd=["ls", "-l"], cwd=EnvironmentVariable("WHERE"), env={"A": "1"})
    exe.prepare(context, None)
    assert exe.final_cmd == ["nice", "-n", "5", "ls", "-l"]
    # launch names it after the first word of the final command, the prefix included
    assert exe.final_name is not None and exe.final_name.startswith("nice-")
    assert exe.final_cwd == "here" and exe.final_env == {"A": "1"}
    context.launch_configurations["launch-prefix-filter"] = "cat"
    exe.prepare(context, None)
    assert exe.final_cmd == ["ls", "-l"]  # the filter excludes ls


def test_lifecycle_transition_registers_then_emits() -> None:
    from launch import LaunchContext
    from launch.actions import EmitEvent as EmitEventAction
    from launch.actions import RegisterEventHandler
    from launch_ros.actions import LifecycleTransition

    with pytest.raises(ValueError):
        LifecycleTransition(lifecycle_node_names=["talker"], transition_ids=[])
    with pytest.raises(ValueError):
        LifecycleTransition(lifecycle_node_names=[], transition_ids=[1])
    context = LaunchContext()
    transition = LifecycleTransition(lifecycle_node_names=["talker"], transition_ids=["1", 3])
    actions = transition.execute(context)
    kinds = [type(a) for a in actions]
    assert kinds == [RegisterEventHandler] * 2 + [EmitEventAction]
    assert actions[-1].event.transition_id == 1
    # the handler of a failed transition is registered with the context, as launch_ros does
    (step,) = context.planner.plan.steps
    assert step.kind == "state_transition"


def test_introspector_draws_a_tree() -> None:
    from launch import LaunchDescription, LaunchIntrospector
    from launch.actions import LogInfo

    text = LaunchIntrospector().format_launch_description(
        LaunchDescription([LogInfo(msg="a"), LogInfo(msg="b")])
    )
    assert text.splitlines()[1:] == ["├── LogInfo('a')", "└── LogInfo('b')"]


def test_an_action_describes_its_sub_entities() -> None:
    from launch.actions import GroupAction, LogInfo
    from launch.conditions import IfCondition

    inner = LogInfo(msg="x")
    # A scoped group's are its actions between what scopes them (tests/test_group_returns.py).
    assert GroupAction([inner], scoped=False).describe_sub_entities() == [inner]
    conditional = GroupAction([inner], scoped=False, condition=IfCondition("true"))
    assert conditional.describe_sub_entities() == []
    ((why, entities),) = conditional.describe_conditional_sub_entities()
    assert why.startswith("Conditionally included by") and list(entities) == [inner]


def test_process_handlers_check_targets_and_call_callables_as_upstream() -> None:
    from launch import LaunchContext
    from launch.actions import ExecuteProcess, LogInfo
    from launch.event_handlers import OnExecutionComplete, OnProcessExit, OnProcessIO
    from launch.events.process import ProcessExited, ProcessIO

    with pytest.raises(TypeError, match="target_action"):
        OnProcessExit(target_action=LogInfo(msg="not a process"), on_exit=[])
    with pytest.raises(TypeError, match="target_action"):
        OnExecutionComplete(target_action="text", on_completion=[])
    with pytest.raises(TypeError, match="launch entities"):
        OnProcessExit(on_exit=["not an action"])
    process = ExecuteProcess(cmd=["true"])
    seen: list[object] = []
    by_name = OnProcessExit(
        target_action=lambda action: action is process,
        on_exit=lambda event, context: seen.append(event),
    )
    event = ProcessExited(action=process, returncode=0)
    assert by_name.matches(event) and not by_name.matches(ProcessExited(action=object()))
    assert by_name.handle(event, LaunchContext()) == [] and seen == [event]

    streams: list[str] = []
    io = OnProcessIO(
        on_stdin=lambda e: streams.append("in"),
        on_stdout=lambda e: streams.append("out"),
        on_stderr=lambda e: streams.append("err"),
    )
    for fd in (0, 1, 2):
        io.handle(ProcessIO(action=process, text=b"x", fd=fd), LaunchContext())
    assert streams == ["in", "out", "err"]


def test_substitution_failures_say_what_launch_says(tmp_path) -> None:  # type: ignore[no-untyped-def]
    from launch import LaunchContext
    from launch.substitutions import EnvironmentVariable, FileContent, ThisLaunchFileDir
    from launch.substitutions.substitution_failure import SubstitutionFailure

    context = LaunchContext(environment={})
    with pytest.raises(SubstitutionFailure, match="environment variable 'NOPE' does not exist"):
        EnvironmentVariable("NOPE").perform(context)
    with pytest.raises(SubstitutionFailure, match="File not found: "):
        FileContent(str(tmp_path / "missing.txt")).perform(context)
    with pytest.raises(SubstitutionFailure):
        ThisLaunchFileDir().perform(context)
    context.extend_locals({"current_launch_file_directory": "foo"})
    assert ThisLaunchFileDir().perform(context) == "foo"


def test_python_expression_errors_are_what_the_expression_raised() -> None:
    from launch import LaunchContext
    from launch.substitutions import PythonExpression
    from launch.substitutions.substitution_failure import SubstitutionFailure

    without_math = PythonExpression(["math.ceil(1.6)"], [])
    with pytest.raises(NameError) as raised:  # as launch lets it through
        without_math.perform(LaunchContext())
    assert isinstance(raised.value, SubstitutionFailure)  # and mlaunch locates it
    assert without_math.describe() == "PythonExpr('math.ceil(1.6)', [])"
    assert PythonExpression("ceil(1.6)").perform(LaunchContext()) == "2"
    assert PythonExpression("1", ["sys", "math"]).describe() == "PythonExpr('1', ['sys', 'math'])"


def test_if_else_reads_a_typed_bool_and_completion_handlers_check_entities() -> None:
    from launch import LaunchContext
    from launch.actions import LogInfo
    from launch.event_handlers import OnExecutionComplete
    from launch.substitutions import IfElseSubstitution

    assert IfElseSubstitution("on", "a", "b").perform(LaunchContext()) == "a"
    assert IfElseSubstitution("0", "a", "b").perform(LaunchContext()) == "b"
    with pytest.raises(TypeError):
        OnExecutionComplete(target_action=LogInfo(msg="m"), on_completion="not an action")


class _ContextLike:
    """Offers only what upstream's code reads of a context (as a test's mock does)."""

    def __init__(self) -> None:
        self.launch_configurations: dict[str, str] = {}

    def get_locals_as_dict(self) -> dict[str, object]:
        return {}

    def perform_substitution(self, substitution: object) -> str:
        return substitution.perform(self)  # type: ignore[attr-defined,no-any-return]


def test_descriptions_and_sources_work_with_a_context_that_has_no_planner(
    tmp_path: Path, caplog: pytest.LogCaptureFixture, monkeypatch: pytest.MonkeyPatch
) -> None:
    import logging

    from launch import LaunchDescription
    from launch.actions import LogInfo
    from launch.launch_description_sources import (
        LaunchDescriptionSource,
        PythonLaunchDescriptionSource,
    )

    # Once launch.logging is imported, a logger first asked for after it is a LaunchLogger, which
    # does not propagate to caplog's handler: whether "launch" is one depends on which tests ran
    # earlier in this process (under xdist, a different set), so the capture must not.
    monkeypatch.setattr(logging.getLogger("launch"), "propagate", True)
    described = LaunchDescription([LogInfo(msg="x")], deprecated_reason="use other.launch.py")
    assert described.visit(_ContextLike()) == described.entities  # type: ignore[arg-type]
    assert "deprecated: use other.launch.py" in caplog.text
    with pytest.raises(RuntimeError, match="no launch description was given"):
        LaunchDescriptionSource().get_launch_description(_ContextLike())  # type: ignore[arg-type]
    given = LaunchDescriptionSource(described, "somewhere")
    assert given.get_launch_description(_ContextLike()) is described  # type: ignore[arg-type]
    assert given.location == "somewhere"
    path = tmp_path / "one.launch.py"
    path.write_text(
        "from launch import LaunchDescription\n"
        "from launch.actions import DeclareLaunchArgument\n"
        "def generate_launch_description():\n"
        "    return LaunchDescription([DeclareLaunchArgument('a')])\n"
    )
    source = PythonLaunchDescriptionSource([str(tmp_path), "/one.launch.py"])
    assert source.location == f"{tmp_path} + /one.launch.py"  # as written until loaded
    loaded = source.get_launch_description(_ContextLike())  # type: ignore[arg-type]
    assert [e.name for e in loaded.entities] == ["a"] and source.location == str(path)


def test_launch_arguments_say_whether_something_may_leave_them_out(tmp_path: Path) -> None:
    from launch import LaunchDescription
    from launch.actions import (
        DeclareLaunchArgument,
        GroupAction,
        IncludeLaunchDescription,
        ResetLaunchConfigurations,
        TimerAction,
    )
    from launch.conditions import IfCondition
    from launch.launch_description_sources import (
        LaunchDescriptionSource,
        PythonLaunchDescriptionSource,
    )

    path = tmp_path / "inner.launch.py"
    path.write_text(
        "from launch import LaunchDescription\n"
        "from launch.actions import DeclareLaunchArgument\n"
        "def generate_launch_description():\n"
        "    return LaunchDescription([DeclareLaunchArgument('from_file')])\n"
    )
    maybe = IfCondition("true")
    described = LaunchDescription(
        [
            DeclareLaunchArgument("plain"),
            DeclareLaunchArgument("own", condition=maybe),
            GroupAction([GroupAction([DeclareLaunchArgument("nested")])], condition=maybe),
            TimerAction(period=1.0, actions=[DeclareLaunchArgument("later")]),
            IncludeLaunchDescription(
                LaunchDescriptionSource(LaunchDescription([DeclareLaunchArgument("given")]))
            ),
            IncludeLaunchDescription(PythonLaunchDescriptionSource(str(path)), condition=maybe),
            DeclareLaunchArgument("plain", condition=maybe),  # the first declaration wins
            ResetLaunchConfigurations(),
            DeclareLaunchArgument("unreachable"),
        ]
    )
    found = {a.name: a._conditionally_included for a in described.get_launch_arguments()}
    assert found == {
        "plain": False,
        "own": True,
        "nested": True,
        "later": True,
        "given": False,
        "from_file": True,
    }
    assert all(a._conditionally_included for a in described.get_launch_arguments(True))
