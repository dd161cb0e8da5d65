"""The tag table shared by the YAML and XML frontends: each tag builds the Python API's action.

A builder reads its Entity through the typed getters (which parse ``$(...)`` once), builds the
same object a ``.launch.py`` file would (mlaunch.launch.actions, and mlaunch.ros for the launch_ros
tags, imported only when such a tag appears) and the dispatcher then adds ``if``/``unless``,
stamps ``origin`` with the tag's file:line and rejects anything left unread.
"""

from __future__ import annotations

from collections.abc import Callable

import mlaunch.launch.actions as core
from mlaunch.errors import LaunchFileError, MlaunchError
from mlaunch.frontends.entity import Attr, Entity, did_you_mean
from mlaunch.frontends.subst import Part, Parts
from mlaunch.launch.conditions import IfCondition, UnlessCondition
from mlaunch.launch.substitutions import Substitution, to_bool
from mlaunch.run.plan import OUTPUT_MODES

TYPE_CHECKING = False  # mypy reads this as typing.TYPE_CHECKING; typing costs ~3 ms
if TYPE_CHECKING:
    from typing import Any

    Builder = Callable[[Entity], Any]
else:  # the same at run time, without typing.Any
    Builder = Callable[[Entity], object]
Value = str | Parts

RESPAWN_WORDS = ("always", "on-failure", "on_failure", "never")


# --- the dispatcher --------------------------------------------------------------------------


def build_description(root: Entity) -> Any:
    """The LaunchDescription of a root ``launch`` entity."""
    if root.tag != "launch":
        raise root.error(f"the root must be 'launch', not {root.tag!r}")
    reason = root.literal("deprecated")
    actions = [build_action(child) for child in root.actions()]
    root.finish()
    description = core.LaunchDescription(actions, deprecated_reason=reason)
    description.origin = root.origin
    return description


def build_action(e: Entity) -> Any:
    """One action tag: its builder, then condition, origin and the completeness check."""
    builder = ACTIONS.get(e.tag)
    if builder is None:
        raise e.error(_unknown_tag(e.tag))
    if e.fmt == "yaml" and e.children is not None and e.tag not in TAKES_ACTIONS:
        raise e.error(f"{e.tag} takes no child entities (only {', '.join(TAKES_ACTIONS)} do)")
    when = e.condition_text("if")
    unless = e.condition_text("unless")
    if when is not None and unless is not None:
        raise e.error("'if' and 'unless' cannot both be given", e.attrs["unless"])
    try:
        action = builder(e)
    except MlaunchError as err:
        # Errors of the action constructors carry no (or a Python) location: point at the tag.
        if not (err.where or "").startswith(e.path):
            err.where, err.what = e.where(), e.what
        raise
    except (TypeError, ValueError) as err:
        raise e.error(f"{type(err).__name__}: {err}")
    if when is not None:
        action.condition = IfCondition(when)
    elif unless is not None:
        action.condition = UnlessCondition(unless)
    action.origin = e.origin
    e.finish()
    return action


def _unknown_tag(tag: str) -> str:
    if tag in UNSUPPORTED:
        return f"the ROS 2 tag {tag!r} is not supported by mlaunch ({UNSUPPORTED[tag]})"
    if tag in MISPLACED:
        return f"{tag!r} is not an action here; {MISPLACED[tag]}"
    hint = did_you_mean(tag, ACTIONS)
    return f"unknown tag {tag!r}{hint}; valid tags: {', '.join(sorted(ACTIONS))}"


def _finish_all(entities: list[Entity]) -> None:
    for entity in entities:
        entity.finish()


def _value(e: Entity, name: str) -> Value:
    value = e.text(name, required=True)
    assert value is not None
    return value


def _key(value: Value) -> Any:
    """A value usable as a dict key (a list of parts becomes a tuple)."""
    return value if isinstance(value, str) else tuple(value)


def _pairs(entities: list[Entity], first: str, second: str) -> list[tuple[Value, Value]]:
    """``<x first=.. second=..>`` sub-entities as (first, second) pairs, each checked."""
    out = []
    for sub in entities:
        out.append((_value(sub, first), _value(sub, second)))
        sub.finish()
    return out


# --- core tags -------------------------------------------------------------------------------


def _arg(e: Entity) -> Any:
    default = e.text("default")
    description_attr = e.attr("description")
    description = None
    if description_attr is not None:
        description = e.scalar_text(description_attr, "description")
    choice_entities = e.subentities("choice")
    choices = [_literal(c, "value") for c in choice_entities]
    _finish_all(choice_entities)
    choices += _yaml_choices(e)
    name = _literal(e, "name")
    return core.DeclareLaunchArgument(
        name, default_value=default, description=description, choices=choices or None
    )


def _literal(e: Entity, name: str) -> str:
    value = e.literal(name, required=True)
    assert value is not None
    return value


def _yaml_choices(e: Entity) -> list[str]:
    """mlaunch extension for YAML: ``choices: [a, b]`` beside ROS 2's ``choice: [{value: a}]``."""
    if e.fmt != "yaml":
        return []
    attr = e.attr("choices")
    if attr is None:
        return []
    node = attr.value
    if type(node).__name__ != "SequenceNode":
        raise e.error("attribute 'choices' must be a list of values", attr)
    if not node.value:
        raise e.error("attribute 'choices' is an empty list", attr)
    out = []
    for item in node.value:
        item_attr = Attr(item, item.start_mark.line + 1, item.start_mark.column + 1)
        text = e.scalar_text(item_attr, "choices")
        if "$(" in text:
            raise e.error(f"a choice must be plain text, got {text!r}", item_attr)
        out.append(text)
    return out


def _let(e: Entity) -> Any:
    return core.SetLaunchConfiguration(_value(e, "name"), _value(e, "value"))


def _include(e: Entity) -> Any:
    from mlaunch.launch.launch_description_sources import AnyLaunchDescriptionSource

    subs = e.subentities("arg") + e.subentities("let")
    subs.sort(key=lambda s: (s.line, s.col))  # XML keeps document order across arg and let
    arguments = _pairs(subs, "name", "value")
    source = AnyLaunchDescriptionSource(_value(e, "file"))
    return core.IncludeLaunchDescription(source, launch_arguments=arguments)


def _group(e: Entity) -> Any:
    scoped = e.flag("scoped")
    forwarding = e.flag("forwarding")
    keep = {_key(k): v for k, v in _pairs(e.subentities("keep"), "name", "value")}
    actions = [build_action(child) for child in e.actions()]
    kwargs: dict[str, Any] = {}
    if scoped is not None:
        kwargs["scoped"] = scoped
    if forwarding is not None:
        kwargs["forwarding"] = forwarding
    if keep:
        kwargs["launch_configurations"] = keep
    return core.GroupAction(actions, **kwargs)


def _timer(e: Entity) -> Any:
    cancel = e.flag("cancel_on_shutdown")
    actions = [build_action(child) for child in e.actions()]
    if not e.has("period"):
        raise e.error("missing required attribute 'period'")
    period: Any = e.number("period", minimum=0.0)
    kwargs: dict[str, Any] = {} if cancel is None else {"cancel_on_shutdown": cancel}
    return core.TimerAction(period=period, actions=actions, **kwargs)


def _set_env(e: Entity) -> Any:
    return core.SetEnvironmentVariable(_value(e, "name"), _value(e, "value"))


def _unset_env(e: Entity) -> Any:
    return core.UnsetEnvironmentVariable(_value(e, "name"))


def _append_env(e: Entity) -> Any:
    kwargs: dict[str, Any] = {}
    prepend = e.flag("prepend")
    if prepend is not None:
        kwargs["prepend"] = prepend
    separator = e.text("separator")
    if separator is not None:
        kwargs["separator"] = separator
    return core.AppendEnvironmentVariable(_value(e, "name"), _value(e, "value"), **kwargs)


def _reset_env(e: Entity) -> Any:
    return core.ResetEnvironment()


def _log(e: Entity) -> Any:
    return core.LogInfo(msg=_value(e, "message"))


def _shutdown(e: Entity) -> Any:
    reason = e.text("reason")
    return core.Shutdown() if reason is None else core.Shutdown(reason=reason)


def _reset(e: Entity) -> Any:
    keep = {_key(k): v for k, v in _pairs(e.subentities("keep"), "name", "value")}
    return core.ResetLaunchConfigurations(keep)


# --- processes -------------------------------------------------------------------------------


def _executable(e: Entity) -> Any:
    kwargs = _process_kwargs(e, label="name")
    cmd = split_command(e, "cmd")
    if not cmd:
        raise e.error("attribute 'cmd' is empty; it names the program to run", e.attrs["cmd"])
    return core.ExecuteProcess(cmd=cmd, **kwargs)


def _process_kwargs(e: Entity, *, label: str | None) -> dict[str, Any]:
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
    env = {_key(k): v for k, v in _pairs(e.subentities("env"), "name", "value")}
    if env:
        kwargs["additional_env"] = env
    return kwargs


def _output(e: Entity) -> Value | None:
    value = e.text("output")
    if isinstance(value, str) and value not in OUTPUT_MODES:
        raise e.error(
            f"output={value!r} is not an output mode; valid: {', '.join(OUTPUT_MODES)}",
            e.attrs["output"],
        )
    return value


def _respawn(e: Entity) -> Any:
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


def split_command(e: Entity, name: str) -> list[Any]:
    """A command-line attribute (``cmd``, ``args``, ``ros_args``) split into argv items.

    Whitespace outside quotes separates items; a substitution joins the item it touches (so
    ``$(find-pkg-share x)/a b`` is two items). Quotes follow the shell's rules, as ROS 2's
    shlex.split does, and may span a substitution (ROS 2 cannot).
    """
    value = e.text(name, required=True)
    assert value is not None
    try:
        return _split(value if isinstance(value, list) else [value])
    except ValueError as err:
        raise e.error(f"attribute {name!r}: {err}", e.attrs[name])


def _split(parts: Parts) -> list[Any]:
    args: list[Any] = []
    current: list[Part] = []
    buf: list[str] = []
    in_token = False
    quote: str | None = None

    def flush() -> None:
        if buf:
            text = "".join(buf)
            buf.clear()
            if current and isinstance(current[-1], str):
                current[-1] += text
            else:
                current.append(text)

    for part in parts:
        if isinstance(part, Substitution):
            flush()
            current.append(part)
            in_token = True
            continue
        i, n = 0, len(part)
        while i < n:
            c = part[i]
            if quote == "'":
                if c == "'":
                    quote = None
                else:
                    buf.append(c)
            elif quote == '"':
                if c == '"':
                    quote = None
                elif c == "\\" and i + 1 < n and part[i + 1] in '"\\':
                    buf.append(part[i + 1])
                    i += 1
                else:
                    buf.append(c)
            elif c.isspace():
                if in_token:
                    flush()
                    args.append(current[0] if len(current) == 1 else list(current))
                    current.clear()
                    in_token = False
            elif c in "'\"":
                quote = c
                in_token = True
            elif c == "\\" and i + 1 < n:
                buf.append(part[i + 1])
                in_token = True
                i += 1
            else:
                buf.append(c)
                in_token = True
            i += 1
    if quote is not None:
        raise ValueError(f"the quote {quote} is not closed")
    if in_token:
        flush()
        args.append(current[0] if len(current) == 1 else (list(current) or ""))
    return args


# --- launch_ros tags -------------------------------------------------------------------------


def _ros_actions() -> Any:
    try:
        import mlaunch.launch_ros.actions as ros
    except ImportError as err:
        raise LaunchFileError(
            f"launch_ros tags need mlaunch.launch_ros.actions, which is missing: {err}"
        )
    return ros


def _node_kwargs(e: Entity) -> dict[str, Any]:
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
    parameters = [_parameter_item(p) for p in e.subentities("param")]
    if parameters:
        kwargs["parameters"] = parameters
    remaps = _pairs(e.subentities("remap"), "from", "to")
    if remaps:
        kwargs["remappings"] = remaps
    kwargs["executable"] = _value(e, "exec")
    return kwargs


def _node(e: Entity) -> Any:
    ros = _ros_actions()
    return ros.Node(**_node_kwargs(e))


def _lifecycle_node(e: Entity) -> Any:
    ros = _ros_actions()
    autostart = e.flag("autostart")
    kwargs = _node_kwargs(e)
    for required in ("name", "namespace"):
        if required not in kwargs:
            raise e.error(f"missing required attribute {required!r} (a lifecycle node needs it)")
    if autostart is not None:
        kwargs["autostart"] = autostart
    return ros.LifecycleNode(**kwargs)


def _push_ros_namespace(e: Entity) -> Any:
    ros = _ros_actions()
    cls = getattr(ros, "PushRosNamespace", None) or ros.PushROSNamespace
    return cls(_value(e, "namespace"))


def _set_parameter(e: Entity) -> Any:
    ros = _ros_actions()
    value = parameter_value(e, typed=False)
    return ros.SetParameter(name=_value(e, "name"), value=value)


def _set_parameters_from_file(e: Entity) -> Any:
    ros = _ros_actions()
    return ros.SetParametersFromFile(_value(e, "filename"))


def _set_remap(e: Entity) -> Any:
    ros = _ros_actions()
    return ros.SetRemap(src=_value(e, "from"), dst=_value(e, "to"))


def _set_use_sim_time(e: Entity) -> Any:
    ros = _ros_actions()
    if not e.has("value"):
        raise e.error("missing required attribute 'value'")
    return ros.SetUseSimTime(e.flag("value"))


def _set_ros_log_dir(e: Entity) -> Any:
    ros = _ros_actions()
    return ros.SetROSLogDir(_value(e, "new_log_dir"))


# --- parameters ------------------------------------------------------------------------------


def _descriptions() -> Any:
    import mlaunch.launch_ros.parameter_descriptions as descriptions

    return descriptions


def _parameter_item(p: Entity) -> Any:
    """One top-level ``param`` of a node: a ParameterFile (``from``) or its own dict."""
    for name in ("name", "value", "type", "value-sep"):
        p.has(name)
    source = p.text("from")
    allow = p.flag("allow_substs")
    if source is not None:
        if "name" in p.attrs:
            raise p.error("'from' and 'name' cannot both be given", p.attrs["name"])
        p.finish()
        return _descriptions().ParameterFile(source, allow_substs=False if allow is None else allow)
    if allow is not None:
        raise p.error("'allow_substs' is only valid with 'from'", p.attrs["allow_substs"])
    if "name" not in p.attrs:
        raise p.error("a param needs 'name' (with 'value' or nested params) or 'from'")
    return dict(_parameter_entries(p, None))


def _parameter_entries(p: Entity, prefix: Value | None) -> list[tuple[Any, Any]]:
    """``name: value`` entries of a param; nested params give dotted names (``a.b.c``)."""
    name = _value(p, "name")
    key = name if prefix is None else _join(prefix, name)
    nested = p.subentities("param")
    entries: list[tuple[Any, Any]] = []
    if nested:
        for what in ("value", "type", "value-sep"):
            if what in p.attrs:
                raise p.error(f"a param with nested params cannot have {what!r}", p.attrs[what])
        for child in nested:
            entries += _parameter_entries(child, key)
    else:
        if "value" not in p.attrs:
            raise p.error(f"param {_show(name)} needs 'value' (or nested params)")
        entries.append((_key(key), parameter_value(p, typed=True)))
    p.finish()
    return entries


def _join(prefix: Value, name: Value) -> Value:
    if isinstance(prefix, str) and isinstance(name, str):
        return f"{prefix}.{name}"
    left = [prefix] if isinstance(prefix, str) else list(prefix)
    right = [name] if isinstance(name, str) else list(name)
    return [*left, ".", *right]


def _show(value: Value) -> str:
    return repr(value) if isinstance(value, str) else "(with substitutions)"


# type= names -> (element type, is a list); "yaml" and no type guess as ROS 2 does.
PARAM_TYPES: dict[str, tuple[type | None, bool]] = {
    "str": (str, False),
    "bool": (bool, False),
    "int": (int, False),
    "float": (float, False),
    "list_of_str": (str, True),
    "list_of_bool": (bool, True),
    "list_of_int": (int, True),
    "list_of_float": (float, True),
    "yaml": (None, False),
}


def parameter_value(p: Entity, *, typed: bool) -> Any:
    """The ``value`` of a param (a ParameterValue) or of set_parameter (the plain value)."""
    type_name = p.literal("type") if typed else None
    if type_name is not None and type_name not in PARAM_TYPES:
        raise p.error(
            f"type={type_name!r} is not a parameter type; valid: {', '.join(PARAM_TYPES)}",
            p.attrs["type"],
        )
    element, is_list = PARAM_TYPES[type_name or "yaml"]
    sep = p.literal("value-sep")
    attr = p.attr("value", required=True)
    assert attr is not None
    value = _typed_value(p, attr, element, is_list, sep)
    if not typed:
        return value
    value_type: Any = None
    if element is not None:
        import typing  # only here: typing costs ~3 ms on every YAML/XML launch

        value_type = typing.List[element] if is_list else element  # type: ignore[valid-type]  # noqa: UP006
    return _descriptions().ParameterValue(value, value_type=value_type)


def _typed_value(
    p: Entity, attr: Attr, element: type | None, is_list: bool, sep: str | None
) -> Any:
    node = attr.value
    kind = type(node).__name__
    if kind == "SequenceNode":  # a YAML list keeps its items' YAML types
        items = [p.yaml_construct(item) for item in node.value]
        return _uniform_list(p, attr, [_yaml_item(p, attr, item, element) for item in items])
    if kind == "MappingNode":
        raise p.error("a parameter value cannot be a map; nest params instead", attr)
    if not isinstance(node, str) and node.tag != "tag:yaml.org,2002:str":
        if node.tag == "tag:yaml.org,2002:null":
            raise p.error('the parameter value is empty (null); write "" for empty text', attr)
        native = p.yaml_construct(node)  # a YAML number or bool keeps its type
        return _coerce(p, attr, native, element, is_list) if element is not None else native
    text = p.scalar_text(attr, "value")
    if sep is not None:
        if not sep:
            raise p.error("value-sep is empty", p.attrs["value-sep"])
        pieces = [_text_item(p, attr, piece, element) for piece in text.split(sep)]
        return _uniform_list(p, attr, pieces)
    if "$(" in text:
        return p.template(attr, text)
    return _coerce(p, attr, text, element, is_list)


def _yaml_item(p: Entity, attr: Attr, item: Any, element: type | None) -> Any:
    if isinstance(item, str) and "$(" in item:
        return p.template(attr, item)
    if isinstance(item, (dict, list)) or item is None:
        raise p.error(f"a list parameter holds plain values, not {item!r}", attr)
    return _coerce(p, attr, item, element, False) if element is not None else item


def _text_item(p: Entity, attr: Attr, piece: str, element: type | None) -> Any:
    """One piece of a value split by value-sep: typed by ``type``, else guessed."""
    if "$(" in piece:
        return p.template(attr, piece)
    if element is None:
        return _guess(piece)
    return _coerce(p, attr, piece, element, False)


def _uniform_list(p: Entity, attr: Attr, items: list[Any]) -> list[Any]:
    """ROS 2 parameters are uniform lists (ints and floats may mix, as floats)."""
    static = [i for i in items if not isinstance(i, (list, Substitution))]
    if static and not _uniform(static):
        kinds = sorted({type(i).__name__ for i in static})
        raise p.error(
            f"a list parameter must hold one type, this one mixes {', '.join(kinds)}: {static!r}",
            attr,
        )
    return items


def _guess(text: str) -> Any:
    """ROS 2's type guess for an untyped value: YAML int, float, bool or uniform list, else str."""
    import yaml

    try:
        value = yaml.safe_load(text)
    except yaml.YAMLError:
        return text
    if isinstance(value, (bool, int, float)):
        return value
    if isinstance(value, list) and value and _uniform(value):
        return value
    return text


def _uniform(items: list[Any]) -> bool:
    kinds = {bool if isinstance(i, bool) else type(i) for i in items}
    return kinds <= {int, float} or (len(kinds) == 1 and kinds <= {bool, int, float, str})


def _coerce(p: Entity, attr: Attr, value: Any, element: type | None, is_list: bool) -> Any:
    """A value forced to the param's ``type``; a wrong one is an error at load time."""
    if element is None:
        return _guess(value) if isinstance(value, str) else value
    if is_list:
        items = _guess_list(p, attr, value)
        return [_coerce(p, attr, item, element, False) for item in items]
    try:
        return _scalar(value, element)
    except ValueError:
        raise p.error(f"parameter value {value!r} is not of type {element.__name__}", attr)


def _guess_list(p: Entity, attr: Attr, value: Any) -> list[Any]:
    if isinstance(value, list):
        return value
    import yaml

    try:
        loaded = yaml.safe_load(value) if isinstance(value, str) else value
    except yaml.YAMLError:
        loaded = None
    if not isinstance(loaded, list):
        raise p.error(
            f"parameter value {value!r} is not a list; write [a, b] or split it with value-sep",
            attr,
        )
    return loaded


def _scalar(value: Any, element: type) -> Any:
    if element is str:
        return value if isinstance(value, str) else _text(value)
    if element is bool:
        if isinstance(value, bool):
            return value
        if isinstance(value, str):
            try:
                return to_bool(value, "value")
            except MlaunchError:
                pass
        raise ValueError(value)
    if isinstance(value, bool):
        raise ValueError(value)
    if element is int:
        if isinstance(value, int):
            return value
        if isinstance(value, str):
            guessed = _guess(value.strip())
            if isinstance(guessed, int) and not isinstance(guessed, bool):
                return guessed
        raise ValueError(value)
    if isinstance(value, (int, float)):
        return float(value)
    guessed = _guess(value.strip()) if isinstance(value, str) else None
    if isinstance(guessed, (int, float)) and not isinstance(guessed, bool):
        return float(guessed)
    raise ValueError(value)


def _text(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    return str(value)


# --- the tables ------------------------------------------------------------------------------

ACTIONS: dict[str, Builder] = {
    "arg": _arg,
    "let": _let,
    "include": _include,
    "group": _group,
    "executable": _executable,
    "set_env": _set_env,
    "unset_env": _unset_env,
    "append_env": _append_env,
    "reset_env": _reset_env,
    "log": _log,
    "timer": _timer,
    "shutdown": _shutdown,
    "reset": _reset,
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

# The tags whose children are actions.
TAKES_ACTIONS = ("group", "timer")

# ROS 2 tags mlaunch knows but does not implement, with what to do instead.
UNSUPPORTED: dict[str, str] = {
    "node_container": "composable node containers are not implemented; run the nodes as <node>",
    "load_composable_node": "composable nodes are not implemented",
    "composable_node": "composable nodes are not implemented",
    "ros_timer": "use <timer>",
}

# Tags that are valid only inside another tag, or only in ROS 1.
MISPLACED: dict[str, str] = {
    "param": "it belongs inside <node>; at the top level use set_parameter",
    "remap": "it belongs inside <node>; at the top level use set_remap",
    "env": "it belongs inside <executable> or <node>; at the top level use set_env",
    "keep": "it belongs inside <group> or <reset>",
    "choice": "it belongs inside <arg>",
    "rosparam": "that is ROS 1 (a .launch file); use <param from=...> inside <node>",
    "machine": "that is ROS 1 (a .launch file)",
    "test": "that is ROS 1 (a .launch file)",
}
