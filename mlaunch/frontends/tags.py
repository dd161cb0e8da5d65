"""The tag table shared by the YAML and XML frontends: each tag builds the Python API's action.

A builder reads its Element through the typed getters (which parse ``$(...)`` once), builds the
same object a ``.launch.py`` file would (mlaunch.launch.actions, and mlaunch.ros for the launch_ros
tags, imported only when such a tag appears) and the dispatcher then adds ``if``/``unless``,
stamps ``origin`` with the tag's file:line and rejects anything left unread.

This module holds the dispatcher and the core ``launch`` tags; the process and launch_ros tags
are in ``process_tags``, the machine tags in ``machine_tags``, the ``param`` values in
``param_tags``.
"""

from __future__ import annotations

import mlaunch.launch.actions as core
from mlaunch.frontends.composition_tags import COMPOSITION_TAGS
from mlaunch.frontends.element import Attr, Element, did_you_mean
from mlaunch.frontends.fields import (
    Builder,
    as_key,
    finish_all,
    pairs,
    required_literal,
    required_text,
)
from mlaunch.frontends.machine_tags import MACHINE_TAGS
from mlaunch.frontends.process_tags import PROCESS_TAGS
from mlaunch.launch.conditions.if_condition import IfCondition
from mlaunch.launch.conditions.unless_condition import UnlessCondition
from mlaunch.plan.errors import MlaunchError

TYPE_CHECKING = False  # mypy reads this as typing.TYPE_CHECKING; typing costs ~3 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.frontend.parser import Parser
    from mlaunch.launch.launch_description import LaunchDescription


# --- the dispatcher --------------------------------------------------------------------------


def build_description(root: Element, parser: Parser | None = None) -> LaunchDescription:
    """The LaunchDescription of a root ``launch`` entity (``parser``: the one tags a package
    exposed are parsed with, when the description is parsed from Python)."""
    if root.tag != "launch":
        raise root.error(f"the root must be 'launch', not {root.tag!r}")
    reason = root.literal("deprecated")
    actions = [build_action(child, parser) for child in root.actions()]
    root.finish()
    description = core.LaunchDescription(actions, deprecated_reason=reason)
    description.origin = root.origin
    return description


def build_action(e: Element, parser: Parser | None = None) -> Any:
    """One action tag: its builder, then condition, origin and the completeness check.

    A tag outside the table is built by the parse method a package exposed for it
    (``launch.frontend.expose_action``), which reads its own condition.
    """
    builder = ACTIONS.get(e.tag)
    if builder is None:
        from mlaunch.frontends.markup import build_exposed

        return build_exposed(e, parser, _unknown_tag)
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
    from mlaunch.launch.frontend.expose import action_parse_methods

    known = {*ACTIONS, *action_parse_methods}  # with the tags packages exposed
    hint = did_you_mean(tag, known)
    return f"unknown tag {tag!r}{hint}; valid tags: {', '.join(sorted(known))}"


# --- core tags -------------------------------------------------------------------------------


def _arg(e: Element) -> Any:
    default = e.text("default")
    description_attr = e.attr("description")
    description = None
    if description_attr is not None:
        description = e.scalar_text(description_attr, "description")
    choice_entities = e.subentities("choice")
    choices = [required_literal(c, "value") for c in choice_entities]
    finish_all(choice_entities)
    choices += _yaml_choices(e)
    name = required_literal(e, "name")
    return core.DeclareLaunchArgument(
        name, default_value=default, description=description, choices=choices or None
    )


def _yaml_choices(e: Element) -> list[str]:
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


def _let(e: Element) -> Any:
    return core.SetLaunchConfiguration(required_text(e, "name"), required_text(e, "value"))


def _include(e: Element) -> Any:
    from mlaunch.launch.launch_description_sources.any_launch_description_source import (
        AnyLaunchDescriptionSource,
    )

    subs = e.subentities("arg") + e.subentities("let")
    subs.sort(key=lambda s: (s.line, s.col))  # XML keeps document order across arg and let
    arguments = pairs(subs, "name", "value")
    source = AnyLaunchDescriptionSource(required_text(e, "file"))
    return core.IncludeLaunchDescription(source, launch_arguments=arguments)


def _group(e: Element) -> Any:
    scoped = e.flag("scoped")
    forwarding = e.flag("forwarding")
    keep = {as_key(k): v for k, v in pairs(e.subentities("keep"), "name", "value")}
    actions = [build_action(child) for child in e.actions()]
    kwargs: dict[str, Any] = {}
    if scoped is not None:
        kwargs["scoped"] = scoped
    if forwarding is not None:
        kwargs["forwarding"] = forwarding
    if keep:
        kwargs["launch_configurations"] = keep
    return core.GroupAction(actions, **kwargs)


def _timer(e: Element) -> Any:
    cancel = e.flag("cancel_on_shutdown")
    actions = [build_action(child) for child in e.actions()]
    if not e.has("period"):
        raise e.error("missing required attribute 'period'")
    period: Any = e.number("period", minimum=0.0)
    kwargs: dict[str, Any] = {} if cancel is None else {"cancel_on_shutdown": cancel}
    return core.TimerAction(period=period, actions=actions, **kwargs)


def _for_each(e: Element) -> Any:
    """``<for_each values="...">``, newer than Jazzy: its children once per set of values."""
    children = [build_action(child) for child in e.actions()]

    def iteration(**values: Any) -> list[Any]:
        return core.ForEach.iteration_entities(children, values)

    return core.ForEach(required_text(e, "values"), function=iteration)


def _for(e: Element) -> Any:
    """``<for len="..." name="...">``, newer than Jazzy: its children ``len`` times."""
    name = required_literal(e, "name")
    children = [build_action(child) for child in e.actions()]

    def iteration(i: int) -> list[Any]:
        return core.ForEach.iteration_entities(children, {name: i})

    return core.ForLoop(required_text(e, "len"), function=iteration, name=name)


def _set_env(e: Element) -> Any:
    return core.SetEnvironmentVariable(required_text(e, "name"), required_text(e, "value"))


def _unset_env(e: Element) -> Any:
    return core.UnsetEnvironmentVariable(required_text(e, "name"))


def _append_env(e: Element) -> Any:
    kwargs: dict[str, Any] = {}
    prepend = e.flag("prepend")
    if prepend is not None:
        kwargs["prepend"] = prepend
    separator = e.text("separator")
    if separator is not None:
        kwargs["separator"] = separator
    return core.AppendEnvironmentVariable(
        required_text(e, "name"), required_text(e, "value"), **kwargs
    )


def _reset_env(e: Element) -> Any:
    return core.ResetEnvironment()


def _log(e: Element) -> Any:
    return core.LogInfo(msg=required_text(e, "message"))


def _shutdown(e: Element) -> Any:
    reason = e.text("reason")
    return core.Shutdown() if reason is None else core.Shutdown(reason=reason)


def _reset(e: Element) -> Any:
    keep = {as_key(k): v for k, v in pairs(e.subentities("keep"), "name", "value")}
    return core.ResetLaunchConfigurations(keep)


# --- the tables ------------------------------------------------------------------------------

ACTIONS: dict[str, Builder] = {
    "arg": _arg,
    "let": _let,
    "include": _include,
    "group": _group,
    "set_env": _set_env,
    "unset_env": _unset_env,
    "append_env": _append_env,
    "reset_env": _reset_env,
    "log": _log,
    "timer": _timer,
    "for_each": _for_each,
    "for": _for,
    "shutdown": _shutdown,
    "reset": _reset,
    **PROCESS_TAGS,
    **MACHINE_TAGS,
    **COMPOSITION_TAGS,
}

# The tags whose children are actions.
TAKES_ACTIONS = ("group", "timer", "for_each", "for")

# ROS 2 tags mlaunch knows but does not implement, with what to do instead.
UNSUPPORTED: dict[str, str] = {
    "ros_timer": "use <timer>",
}

# Tags that are valid only inside another tag, or only in ROS 1.
MISPLACED: dict[str, str] = {
    "param": "it belongs inside <node>; at the top level use set_parameter",
    "remap": "it belongs inside <node>; at the top level use set_remap",
    "env": "it belongs inside <executable> or <node>; at the top level use set_env",
    "keep": "it belongs inside <group> or <reset>",
    "composable_node": "it belongs inside <node_container> or <load_composable_node>",
    "choice": "it belongs inside <arg>",
    "rosparam": "that is ROS 1 (a .launch file); use <param from=...> inside <node>",
    "test": "that is ROS 1 (a .launch file)",
}
