"""The process tags of YAML/XML launch files (``executable``, ``node``, ``lifecycle_node``) and
the launch_ros tags that set scope (namespace, parameters, remaps, sim time, log folder).

The launch_ros actions are imported only when such a tag appears.
"""

from __future__ import annotations

import mlaunch.launch.actions as core
from mlaunch.frontends.element import Element
from mlaunch.frontends.fields import Builder, Value, as_key, pairs, required_text
from mlaunch.frontends.param_tags import parameter_item, parameter_value
from mlaunch.launch.frontend.cmdline import split_parts
from mlaunch.launch.substitutions.boolean_substitution import to_bool
from mlaunch.plan.errors import MlaunchError
from mlaunch.plan.steps import OUTPUT_MODES

TYPE_CHECKING = False  # mypy reads this as typing.TYPE_CHECKING; typing costs ~3 ms
if TYPE_CHECKING:
    from typing import Any

RESPAWN_WORDS = ("always", "on-failure", "on_failure", "never")


def _executable(e: Element) -> Any:
    kwargs = _process_kwargs(e, label="name")
    cmd = split_command(e, "cmd")
    if not cmd or cmd == [""]:  # blank: ros2 launch would try to run the program ''
        raise e.error("attribute 'cmd' is empty; it names the program to run", e.attrs["cmd"])
    return core.ExecuteProcess(cmd=cmd, **kwargs)


def _process_kwargs(e: Element, *, label: str | None) -> dict[str, Any]:
    """The ExecuteProcess keywords every process tag shares (executable, node, lifecycle_node)."""
    kwargs: dict[str, Any] = {}

    def put(key: str, value: Any) -> None:
        if value is not None:
            kwargs[key] = value

    if label is not None:
        put("name", e.text(label))
    put("cwd", e.text("cwd"))
    put("prefix", e.text("launch-prefix"))
    put("output", _output(e))
    put("shell", e.flag("shell", dynamic=False))
    put("emulate_tty", e.flag("emulate_tty"))
    put("respawn", _respawn(e))
    put("respawn_delay", e.number("respawn_delay", minimum=0.0))
    put("respawn_max_retries", e.number("respawn_max_retries", int))
    put("sigterm_timeout", e.number("sigterm_timeout", minimum=0.0))
    put("sigkill_timeout", e.number("sigkill_timeout", minimum=0.0))
    put("required", e.flag("required"))
    put("machine", e.text("machine"))
    on_exit = e.literal("on_exit")
    if on_exit is not None:
        if on_exit != "shutdown":
            raise e.error(
                f"on_exit={on_exit!r} is not supported; the only value is 'shutdown'",
                e.attrs["on_exit"],
            )
        shutdown = core.Shutdown()
        shutdown.origin = e.origin
        kwargs["on_exit"] = [shutdown]
    env = {as_key(k): v for k, v in pairs(e.subentities("env"), "name", "value")}
    if env:
        kwargs["additional_env"] = env
    return kwargs


def _output(e: Element) -> Value | None:
    value = e.text("output")
    if isinstance(value, str) and value not in OUTPUT_MODES:
        raise e.error(
            f"output={value!r} is not an output mode; valid: {', '.join(OUTPUT_MODES)}",
            e.attrs["output"],
        )
    return value


def _respawn(e: Element) -> Any:
    """A bool, mlaunch's always/on-failure/never, or substitutions performed to one of them."""
    attr = e.attrs.get("respawn")
    if attr is not None and e.yaml_native(attr, ("tag:yaml.org,2002:bool",)) is not None:
        return e.flag("respawn")
    value = e.text("respawn")
    if not isinstance(value, str):
        return value
    if value.strip().lower() in RESPAWN_WORDS:
        return value.strip().lower()
    try:
        return to_bool(value, "respawn")
    except MlaunchError:
        raise e.error(
            f"respawn={value!r} is not valid; valid: true, false, always, on-failure, never",
            e.attrs["respawn"],
        )


def split_command(e: Element, name: str) -> list[Any]:
    """A command-line attribute (``cmd``, ``args``, ``ros_args``) split into argv items.

    Whitespace outside quotes separates items; a substitution joins the item it touches (so
    ``$(find-pkg-share x)/a b`` is two items). Quotes follow the shell's rules, as ROS 2's
    shlex.split does, and may span a substitution (ROS 2 cannot).
    """
    value = e.text(name, required=True)
    assert value is not None
    try:
        return split_parts(value if isinstance(value, list) else [value])
    except ValueError as err:
        raise e.error(f"attribute {name!r}: {err}", e.attrs[name])


# --- launch_ros tags -------------------------------------------------------------------------


def _ros_actions() -> Any:
    import mlaunch.launch_ros.actions as ros  # loaded only by files with launch_ros tags

    return ros


def node_kwargs(e: Element) -> dict[str, Any]:
    kwargs = _process_kwargs(e, label=None)

    def put(key: str, value: Any) -> None:
        if value is not None:
            kwargs[key] = value

    put("exec_name", e.text("exec_name"))
    put("name", e.text("name"))
    put("namespace", e.text("namespace"))
    put("package", e.text("pkg"))
    if e.has("args"):
        kwargs["arguments"] = split_command(e, "args")
    if e.has("ros_args"):
        kwargs["ros_arguments"] = split_command(e, "ros_args")
    parameters = [parameter_item(p) for p in e.subentities("param")]
    if parameters:
        kwargs["parameters"] = parameters
    remaps = pairs(e.subentities("remap"), "from", "to")
    if remaps:
        kwargs["remappings"] = remaps
    kwargs["executable"] = required_text(e, "exec")
    return kwargs


def _node(e: Element) -> Any:
    ros = _ros_actions()
    return ros.Node(**node_kwargs(e))


def _lifecycle_node(e: Element) -> Any:
    ros = _ros_actions()
    autostart = e.flag("autostart")
    kwargs = node_kwargs(e)
    for required in ("name", "namespace"):
        if required not in kwargs:
            raise e.error(f"missing required attribute {required!r} (a lifecycle node needs it)")
    if autostart is not None:
        kwargs["autostart"] = autostart
    return ros.LifecycleNode(**kwargs)


def _push_ros_namespace(e: Element) -> Any:
    ros = _ros_actions()
    cls = getattr(ros, "PushRosNamespace", None) or ros.PushROSNamespace
    return cls(required_text(e, "namespace"))


def _set_parameter(e: Element) -> Any:
    ros = _ros_actions()
    value = parameter_value(e, typed=False)
    return ros.SetParameter(name=required_text(e, "name"), value=value)


def _set_parameters_from_file(e: Element) -> Any:
    ros = _ros_actions()
    return ros.SetParametersFromFile(required_text(e, "filename"))


def _set_remap(e: Element) -> Any:
    ros = _ros_actions()
    return ros.SetRemap(src=required_text(e, "from"), dst=required_text(e, "to"))


def _set_use_sim_time(e: Element) -> Any:
    ros = _ros_actions()
    if not e.has("value"):
        raise e.error("missing required attribute 'value'")
    return ros.SetUseSimTime(e.flag("value"))


def _set_ros_log_dir(e: Element) -> Any:
    ros = _ros_actions()
    return ros.SetROSLogDir(required_text(e, "new_log_dir"))


# The process and launch_ros tags of the tag table (``mlaunch.frontends.tags.ACTIONS``).
PROCESS_TAGS: dict[str, Builder] = {
    "executable": _executable,
    "node": _node,
    "lifecycle_node": _lifecycle_node,
    "push-ros-namespace": _push_ros_namespace,
    "push_ros_namespace": _push_ros_namespace,
    "set_parameter": _set_parameter,
    "set_parameters_from_file": _set_parameters_from_file,
    "set_remap": _set_remap,
    "set_use_sim_time": _set_use_sim_time,
    "set_ros_log_dir": _set_ros_log_dir,
}
