"""The model of a roslaunch file built into mlaunch's actions (the ROS 2 classes)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from mlaunch.launch.actions.set_launch_configuration import SetLaunchConfiguration
from mlaunch.launch_ros.parameter_descriptions import ParameterValue
from mlaunch.ros1.actions import (
    GlobalParameter,
    LoadParameterServer,
    MappingWarning,
    RoslaunchNode,
    RoslaunchSource,
    RoslaunchValue,
    ScopeNote,
)
from mlaunch.ros1.eval import RoslaunchEval
from mlaunch.ros1.model import (
    MACHINE_FIELDS,
    AnonRef,
    ArgRef,
    CommandRef,
    Cond,
    DeclareArg,
    DirnameRef,
    Dropped,
    EnvRef,
    EvalRef,
    ExecRef,
    FileRef,
    FindRef,
    Group,
    Include,
    Item,
    MachineItem,
    NodeItem,
    Part,
    Process,
    ProcessItem,
    PValue,
    SetArg,
    SetEnv,
    SetParam,
    SetRemap,
    Value,
    Warn,
    rel_origin,
    static_text,
)

if TYPE_CHECKING:
    from mlaunch.launch.launch_context import LaunchContext


class ConstantArgument(SetLaunchConfiguration):
    """roslaunch's ``<arg value=...>``: a constant the command line cannot change."""

    def __init__(self, name: str, value: Any) -> None:
        super().__init__(name, value)
        self.arg_name = name

    def execute(self, context: LaunchContext) -> None:
        planner = context.planner
        given = {a.split(":=", 1)[0] for a in context.argv}
        if self.arg_name in given:
            planner.warn(
                f"{rel_origin(self.origin)}: arg {self.arg_name!r} has a fixed value in the launch"
                " file; the command-line value is ignored (roslaunch refuses to override it)"
            )
        super().execute(context)


def description_actions(path: str, items: list[Item]) -> list[Any]:
    """A whole roslaunch file's actions: its parameter server first, then the model's."""
    return [LoadParameterServer(path, sorted(declared_args(items))), *to_actions(items)]


def declared_args(items: list[Item]) -> set[str]:
    """The names of the file's ``<arg>``s that take a value from outside (not constants)."""
    found: set[str] = set()
    for item in items:
        if isinstance(item, DeclareArg):
            found.add(item.name)
        elif isinstance(item, Group):
            found |= declared_args(item.items)
    return found


def to_actions(items: list[Item]) -> list[Any]:
    """The model as mlaunch's actions (the ROS 2 classes a converted file would use)."""
    out: list[Any] = []
    for item in items:
        condition = _condition(item.condition)
        # A dropped node: why it is dropped is what matters where it runs.
        messages = item.warnings[:1] if isinstance(item, Dropped) else item.warnings
        for message in messages:
            out.append(MappingWarning(message, item.origin, _condition(item.condition)))
        for message in item.scope_notes:
            out.append(ScopeNote(message, item.origin, _condition(item.condition)))
        action = _action(item)
        if action is None:
            continue
        action.condition = condition
        action.origin = item.origin
        out.append(action)
    return out


def _action(item: Item) -> Any:
    import mlaunch.launch.actions as core
    import mlaunch.launch_ros.actions as ros

    if isinstance(item, Warn):
        return (ScopeNote if item.scope_note else MappingWarning)(item.message, item.origin, None)
    if isinstance(item, Dropped):
        return None
    if isinstance(item, DeclareArg):
        default = None if item.default is None else subs(item.default)
        return core.DeclareLaunchArgument(item.name, default_value=default, description=item.doc)
    if isinstance(item, SetArg):
        return ConstantArgument(item.name, subs(item.value))
    if isinstance(item, SetParam):
        return GlobalParameter(name=subs(item.name), value=parameter_value(item.value))
    if isinstance(item, SetRemap):
        remap = ros.SetRemap(src=subs(item.src), dst=subs(item.dst))
        remap.keep_in_scope = True  # ROS 1 remaps belong to their group
        return remap
    if isinstance(item, SetEnv):
        return core.SetEnvironmentVariable(subs(item.name), subs(item.value))
    if isinstance(item, Group):
        actions = to_actions(item.items)
        if item.namespace is not None:
            push = ros.PushROSNamespace(subs(item.namespace))
            push.origin = item.origin
            actions.insert(0, push)
        return core.GroupAction(actions, scoped=item.scoped)
    if isinstance(item, Include):
        source = RoslaunchSource(subs(item.path))
        arguments = [(name, subs(value)) for name, value in item.arguments]
        include = core.IncludeLaunchDescription(source, launch_arguments=arguments)
        include.keep_file_locals = True  # roslaunch's $(dirname) in an arg is the includer's
        return include
    if isinstance(item, MachineItem):
        from mlaunch.machines.actions import Machine

        optional = {k: subs(getattr(item, k)) for k, _ in MACHINE_FIELDS if getattr(item, k)}
        return Machine(
            name=subs(item.name), address=subs(item.address), ros1_default=True, **optional
        )
    if isinstance(item, NodeItem):
        keywords = node_keywords(item)
        shell_args = None
        if item.shell_args is not None:
            keywords.pop("arguments", None)
            shell_args = subs(item.shell_args)
        package = static_text(item.package) or ""
        node = RoslaunchNode(shell_args=shell_args, ros1_package=package, **keywords)
        node.follows_ros1_default = True
        return node
    if isinstance(item, ProcessItem):
        process = core.ExecuteProcess(cmd=[subs(c) for c in item.cmd], **process_keywords(item))
        process.follows_ros1_default = True
        return process
    raise TypeError(f"unknown item {item!r}")


def node_keywords(node: NodeItem) -> dict[str, Any]:
    kwargs = process_keywords(node)
    kwargs["package"] = subs(node.package)
    kwargs["executable"] = subs(node.executable)
    if node.name is not None:
        kwargs["name"] = subs(node.name)
    if node.namespace is not None:
        kwargs["namespace"] = subs(node.namespace)
    if node.arguments:
        kwargs["arguments"] = [subs(a) for a in node.arguments]
    if node.parameters:
        kwargs["parameters"] = [
            {_key(name): parameter_value(value) for name, value in node.parameters}
        ]
    if node.remappings:
        kwargs["remappings"] = [(subs(a), subs(b)) for a, b in node.remappings]
    return kwargs


def process_keywords(item: Process) -> dict[str, Any]:
    import mlaunch.launch.actions as core

    kwargs: dict[str, Any] = {}
    if item.output is not None:
        kwargs["output"] = subs(item.output)
    if item.respawn is not False:
        kwargs["respawn"] = item.respawn if item.respawn is True else subs(item.respawn)
    if item.respawn_delay is not None:
        delay = item.respawn_delay
        kwargs["respawn_delay"] = delay if isinstance(delay, float) else subs(delay)
    if item.required is True:
        kwargs["on_exit"] = [core.Shutdown()]
    elif item.required is not False:
        kwargs["required"] = subs(item.required)
    if item.prefix is not None:
        kwargs["prefix"] = subs(item.prefix)
    if item.env:
        kwargs["additional_env"] = {_key(k): subs(v) for k, v in item.env}
    if item.machine is not None:
        kwargs["machine"] = subs(item.machine)
    return kwargs


def _key(value: Value) -> Any:
    """A dict key: the text, or a tuple of text and substitutions."""
    converted = subs(value)
    if len(converted) == 1 and isinstance(converted[0], str):
        return converted[0]
    return tuple(converted)


def _condition(cond: Cond | None) -> Any:
    if cond is None:
        return None
    from mlaunch.launch.conditions.if_condition import IfCondition
    from mlaunch.launch.conditions.unless_condition import UnlessCondition

    return (UnlessCondition if cond.unless else IfCondition)(subs(cond.value))


def parameter_value(value: PValue) -> Any:
    """A parameter value as Node(parameters=...) and SetParameter take it."""
    if value.dynamic is None:
        return value.literal
    converted = subs(value.dynamic)
    if value.auto:
        return RoslaunchValue(converted)
    if value.vtype is None:
        return converted
    return ParameterValue(converted, value_type=value.vtype)


def subs(value: Value) -> list[Any]:
    """A value as ROS 2 substitutions (a list: text and substitutions concatenate)."""
    return [_substitution(p) for p in value] if value else [""]


def _substitution(part: Part) -> Any:
    import mlaunch.launch.substitutions as core

    if isinstance(part, str):
        return part
    if isinstance(part, ArgRef):
        return core.LaunchConfiguration(part.name)
    if isinstance(part, FindRef):
        from mlaunch.launch_ros.substitutions.find_package import FindPackageShare

        return FindPackageShare(part.package)
    if isinstance(part, ExecRef):
        from mlaunch.launch_ros.substitutions.executable_in_package import ExecutableInPackage

        return ExecutableInPackage(part.executable, part.package)
    if isinstance(part, EnvRef):
        return core.EnvironmentVariable(part.name, default_value=part.default)
    if isinstance(part, AnonRef):
        return core.AnonName(part.name)
    if isinstance(part, DirnameRef):
        return core.ThisLaunchFileDir()
    if isinstance(part, EvalRef):
        return RoslaunchEval(part.expression)
    if isinstance(part, CommandRef):
        import mlaunch.launch_ros.xacro  # noqa: F401  (xacro runs in-process for Command)

        return core.Command(subs(part.command), on_stderr="warn")
    if isinstance(part, FileRef):
        return core.FileContent(subs(part.path))
    raise TypeError(f"unknown substitution {part!r}")
