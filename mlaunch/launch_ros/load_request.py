"""The LoadNode request of one composable node, built as launch_ros builds it.

``composition_interfaces/srv/LoadNode`` carries the package and plugin, the node's name and
namespace (the pushed namespace in front), a log level launch_ros never sets (0), remap rules
(the global ``SetRemap`` rules first, then the node's own, each ``from:=to``), and parameters and
extra arguments as typed ``rcl_interfaces/Parameter`` entries. Parameters are flattened as
launch_ros flattens them: global parameters first, then the node's entries in order; a dict
gives its own entries, a params file gives its ``/**`` section updated with the section of the
node's ``namespace/name`` (only when the node's name is given), and a file with no
``ros__parameters`` at all gives its whole content. launch_ros quirk kept: a params file that
has no section for the node repeats the entries of the entry before it (the request is compared
with the reference's, and a repeated value sets the same parameter twice).

Built with nothing but PyYAML: the request is a Value (plain data), turned into the rosidl
message only by the driver (``to_message``), so ``--print`` works without rclpy.
"""

from __future__ import annotations

import os
from pathlib import Path

from mlaunch.launch.substitution import perform_substitutions
from mlaunch.launch_ros import params
from mlaunch.launch_ros.parameter_descriptions import Parameter, ParameterFile
from mlaunch.launch_ros.scope import make_namespace_absolute, prefix_namespace
from mlaunch.plan.errors import MlaunchError, SubstitutionFailure
from mlaunch.plan.value import Value

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext
    from mlaunch.launch_ros.descriptions.composable_node import ComposableNode

# rcl_interfaces/msg/ParameterType, in the order rclpy tries them on a value.
NOT_SET, BOOL, INTEGER, DOUBLE, STRING = 0, 1, 2, 3, 4
BYTE_ARRAY, BOOL_ARRAY, INTEGER_ARRAY, DOUBLE_ARRAY, STRING_ARRAY = 5, 6, 7, 8, 9
TYPE_NAMES = {
    NOT_SET: "not set",
    BOOL: "bool",
    INTEGER: "integer",
    DOUBLE: "double",
    STRING: "string",
    BYTE_ARRAY: "byte[]",
    BOOL_ARRAY: "bool[]",
    INTEGER_ARRAY: "integer[]",
    DOUBLE_ARRAY: "double[]",
    STRING_ARRAY: "string[]",
}


class TypedParameter(Value):
    """One ``rcl_interfaces/Parameter``: name, ParameterType code and the value."""

    _fields = ("name", "type", "value")
    __slots__ = _fields

    def __init__(self, name: str, type: int, value: Any) -> None:
        self.name = name
        self.type = type
        self.value = value


class LoadRequest(Value):
    """The fields of one ``composition_interfaces/srv/LoadNode`` request."""

    _fields = (
        "package_name",
        "plugin_name",
        "node_name",
        "node_namespace",
        "log_level",
        "remap_rules",
        "parameters",
        "extra_arguments",
    )
    # autostart: what the launch does once the node is loaded (a ComposableLifecycleNode's: it
    # configures and activates it), not part of the message, so not a field.
    __slots__ = (*_fields, "autostart")

    def __init__(
        self,
        package_name: str,
        plugin_name: str,
        node_name: str = "",
        node_namespace: str = "",
        log_level: int = 0,
        remap_rules: tuple[str, ...] = (),
        parameters: tuple[TypedParameter, ...] = (),
        extra_arguments: tuple[TypedParameter, ...] = (),
        autostart: bool = False,
    ) -> None:
        self.autostart = autostart
        self.package_name = package_name
        self.plugin_name = plugin_name
        self.node_name = node_name
        self.node_namespace = node_namespace
        self.log_level = log_level
        self.remap_rules = remap_rules
        self.parameters = parameters
        self.extra_arguments = extra_arguments

    @property
    def full_name(self) -> str:
        """``namespace/name`` as far as known (the container picks a missing name)."""
        name = self.node_name or f"<{self.plugin_name}'s default name>"
        return prefix_namespace(self.node_namespace or "/", name) or name


def load_request(description: ComposableNode, context: LaunchContext) -> LoadRequest | None:
    """The request for ``description`` in ``context``, or None when its condition is false."""
    condition = description.condition()
    if condition is not None and not condition.evaluate(context):
        return None
    package = perform_substitutions(context, description.package)
    plugin = perform_substitutions(context, description.node_plugin)
    name = ""
    if description.node_name is not None:
        name = perform_substitutions(context, description.node_name)
    given = None
    if description.node_namespace is not None:
        given = perform_substitutions(context, description.node_namespace)
    pushed = context.launch_configurations.get("ros_namespace")
    namespace = make_namespace_absolute_or_none(prefix_namespace(pushed, given))
    remaps = [f"{src}:={dst}" for src, dst in context.launch_configurations.get("ros_remaps") or ()]
    for src, dst in description.remappings or ():
        remaps.append(
            f"{perform_substitutions(context, src)}:={perform_substitutions(context, dst)}"
        )
    entries: list[Any] = [*_global_entries(context), *(description.parameters or ())]
    typed_params = flatten(context, entries, name, namespace) if entries else []
    extra = []
    if description.extra_arguments is not None:
        extra = flatten(
            context, description.extra_arguments, name, namespace, field="extra_arguments"
        )
    autostarts = getattr(description, "autostarts", None)  # a ComposableLifecycleNode's
    return LoadRequest(
        package_name=package,
        plugin_name=plugin,
        node_name=name,
        node_namespace=namespace or "",
        remap_rules=tuple(remaps),
        parameters=tuple(typed_params),
        extra_arguments=tuple(extra),
        autostart=bool(autostarts(context)) if autostarts is not None else False,
    )


def make_namespace_absolute_or_none(namespace: str | None) -> str | None:
    return None if namespace is None else make_namespace_absolute(namespace)


def _global_entries(context: LaunchContext) -> list[Any]:
    """SetParameter / SetParametersFromFile globals as parameters entries (dicts, files)."""
    out: list[Any] = []
    for entry in context.launch_configurations.get("global_params") or ():
        if isinstance(entry, tuple):
            out.append(params.normalize_dict({entry[0]: entry[1]}))
            continue
        path = Path(str(entry)).resolve()
        if not path.is_file():
            raise SubstitutionFailure(f"global parameters file {str(path)!r} does not exist")
        out.append(ParameterFile(path))
    return out


def flatten(
    context: LaunchContext,
    entries: Any,
    node_name: str,
    namespace: str | None,
    field: str = "parameters",
) -> list[TypedParameter]:
    """Parameters entries (dicts, files) as typed name/value pairs, in order.

    A ``Parameter(...)`` description is refused as launch_ros 0.26.6 refuses it: its request
    builder keeps the object unevaluated and fails on it ('invalid evaluated parameters'),
    ending the launch; mlaunch says so before anything starts.
    """
    key = node_name.lstrip("/")
    if namespace and namespace != "/":
        key = f"{namespace.strip('/')}/{key}"
    out: list[TypedParameter] = []
    current: dict[str, Any] = {}
    for entry in entries:
        if isinstance(entry, ParameterFile):
            section = _file_entry_section(context, entry, key)
            if section is not None:
                current = section
            # else: launch_ros adds the entries before this file again (see the module text).
        elif isinstance(entry, Parameter):
            raise MlaunchError(
                f"a ComposableNode's {field} cannot hold {entry}: launch_ros fails to load"
                " the node ('invalid evaluated parameters') and ends the launch; give it as a"
                f" dict instead, {field}=[{{name: value}}]"
            )
        else:
            current = params.evaluate_dict(context, entry)
        for name, value in current.items():
            kind = parameter_type(name, value)
            out.append(TypedParameter(name, kind, tuple(value) if kind >= BYTE_ARRAY else value))
    return out


def _file_entry_section(
    context: LaunchContext, entry: ParameterFile, key: str
) -> dict[str, Any] | None:
    """``_file_section`` of a ParameterFile entry; its substituted copy, read here and nowhere
    else (the request carries the values), is removed once read."""
    path = entry.evaluate(context)
    try:
        return _file_section(context, path, key)
    finally:
        if entry.created:
            try:
                os.unlink(path)
            except OSError:
                pass  # already gone: nothing to tidy


def _file_section(context: LaunchContext, path: Path, key: str) -> dict[str, Any] | None:
    """The parameters a params file gives the node ``key``, None when it gives none."""
    import yaml

    from mlaunch.plan.yamldata import load as load_yaml

    try:
        with open(path, encoding="utf-8") as f:
            data = load_yaml(f.read(), str(path))
    except OSError as e:
        raise SubstitutionFailure(f"parameter file {str(path)!r} cannot be read: {e.strerror}")
    except yaml.YAMLError as e:
        raise SubstitutionFailure(f"parameter file {str(path)!r} is not valid YAML: {e}")
    if not isinstance(data, dict):
        return None
    sections = _sections(data, [], {})
    chosen: dict[Any, Any] = data
    if sections:
        chosen = dict(sections.get("**") or {})
        chosen.update(sections.get(key) or {})
    if not chosen:
        return None
    if not isinstance(chosen, dict):
        raise SubstitutionFailure(
            f"parameter file {str(path)!r}: ros__parameters of {key!r} is not a mapping"
        )
    # A file's use_sim_time goes out as written: launch_ros does not check it (nor does mlaunch
    # for a Node's params file, which the node reads itself); the container answers the load.
    return params.evaluate_dict(context, params.normalize_dict(chosen), check_clock=False)


def _sections(data: dict[Any, Any], keys: list[str], out: dict[str, Any]) -> dict[str, Any]:
    """``{'ns/node': {...}}`` of every ``ros__parameters`` (node keys joined, '/' stripped)."""
    for k, value in data.items():
        if k == "ros__parameters":
            out["/".join(keys)] = value
            return out
        if isinstance(value, dict):
            keys.append(str(k).lstrip("/"))
            _sections(value, keys, out)
            keys.pop()
    return out


def parameter_type(name: str, value: Any) -> int:
    """The ParameterType rclpy gives ``value`` (its first matching type), or a clear error."""
    if value is None:
        return NOT_SET
    if isinstance(value, bool):
        return BOOL
    if isinstance(value, int):
        return INTEGER
    if isinstance(value, float):
        return DOUBLE
    if isinstance(value, str):
        return STRING
    if isinstance(value, (list, tuple)):
        if all(isinstance(v, bytes) and len(v) == 1 for v in value):
            return BYTE_ARRAY
        for kind, code in ((bool, BOOL_ARRAY), (int, INTEGER_ARRAY), (float, DOUBLE_ARRAY)):
            if all(isinstance(v, kind) for v in value):
                return code
        if all(isinstance(v, str) for v in value):
            return STRING_ARRAY
    raise SubstitutionFailure(
        f"parameter {name!r} has the value {value!r:.120} ({type(value).__name__}), which a"
        " LoadNode request cannot carry: allowed are bool, int, float, str and lists of one of them"
    )


def describe_request(request: LoadRequest, container: str, origin: str) -> list[str]:
    """--print lines of one component load, as a process is shown."""
    from mlaunch.plan.text import rel, shorten, value_text

    lines = [
        f"component {request.full_name}   (loaded into {container})"
        + (f"   {rel(origin)}" if origin else ""),
        f"  plugin:  {request.plugin_name}   (package {request.package_name})",
    ]
    for rule in request.remap_rules:
        lines.append(f"  remap:   {rule}")
    for p in request.parameters:
        lines.append(f"  param:   {p.name} = {shorten(value_text(_listed(p.value)), 120)}")
    for p in request.extra_arguments:
        lines.append(f"  extra:   {p.name} = {value_text(_listed(p.value))}")
    if request.autostart:
        lines.append("  lifecycle: autostart (configured and activated once loaded)")
    return lines


def request_data(request: LoadRequest) -> dict[str, Any]:
    """--print --format json: one component load as data (mlaunch.resolve.plan_json)."""
    from mlaunch.plan.text import json_safe

    def typed(p: TypedParameter) -> dict[str, Any]:
        return {"name": p.name, "value": json_safe(p.value), "type": TYPE_NAMES[p.type]}

    named = bool(request.node_name)
    data = {
        "package": request.package_name,
        "plugin": request.plugin_name,
        "name": request.node_name if named else None,
        "namespace": request.node_namespace or None,
        "full_name": request.full_name if named else None,
        "log_level": request.log_level,
        "remaps": [
            {"from": rule.partition(":=")[0], "to": rule.partition(":=")[2]}
            for rule in request.remap_rules
        ],
        "parameters": [typed(p) for p in request.parameters],
        "extra_arguments": [typed(p) for p in request.extra_arguments],
    }
    if request.autostart:  # only then, so plans without lifecycle components read as before
        data["autostart"] = True
    return data


def _listed(value: Any) -> Any:
    return list(value) if isinstance(value, tuple) else value


def to_message(request: LoadRequest) -> Any:
    """The rosidl ``LoadNode.Request`` (needs the built composition_interfaces and rclpy)."""
    from composition_interfaces.srv import LoadNode

    msg = LoadNode.Request()
    msg.package_name = request.package_name
    msg.plugin_name = request.plugin_name
    msg.node_name = request.node_name
    msg.node_namespace = request.node_namespace
    msg.log_level = request.log_level
    msg.remap_rules = list(request.remap_rules)
    msg.parameters = [_parameter_message(p) for p in request.parameters]
    msg.extra_arguments = [_parameter_message(p) for p in request.extra_arguments]
    return msg


_VALUE_FIELDS = {
    BOOL: "bool_value",
    INTEGER: "integer_value",
    DOUBLE: "double_value",
    STRING: "string_value",
    BYTE_ARRAY: "byte_array_value",
    BOOL_ARRAY: "bool_array_value",
    INTEGER_ARRAY: "integer_array_value",
    DOUBLE_ARRAY: "double_array_value",
    STRING_ARRAY: "string_array_value",
}


def _parameter_message(p: TypedParameter) -> Any:
    from rcl_interfaces.msg import Parameter as ParameterMsg
    from rcl_interfaces.msg import ParameterValue

    value = ParameterValue(type=p.type)
    if p.type in _VALUE_FIELDS:
        setattr(value, _VALUE_FIELDS[p.type], list(p.value) if p.type >= BYTE_ARRAY else p.value)
    return ParameterMsg(name=p.name, value=value)


def from_message(msg: Any) -> LoadRequest:
    """A received ``LoadNode.Request`` as a LoadRequest (recording containers, tests)."""

    def typed(p: Any) -> TypedParameter:
        field = _VALUE_FIELDS.get(p.value.type)
        value = None if field is None else getattr(p.value, field)
        if value is not None and p.value.type >= BYTE_ARRAY:
            value = tuple(value)
        return TypedParameter(p.name, p.value.type, value)

    return LoadRequest(
        package_name=msg.package_name,
        plugin_name=msg.plugin_name,
        node_name=msg.node_name,
        node_namespace=msg.node_namespace,
        log_level=msg.log_level,
        remap_rules=tuple(msg.remap_rules),
        parameters=tuple(typed(p) for p in msg.parameters),
        extra_arguments=tuple(typed(p) for p in msg.extra_arguments),
    )
