"""The composition tags of YAML/XML launch files: ``node_container``, ``load_composable_node``
and their ``composable_node`` children, read as launch_ros reads them.

``node_container`` takes every attribute and child of ``node`` plus ``composable_node``
children; ``load_composable_node`` takes ``target`` (the container's name) and
``composable_node`` children. A ``composable_node`` takes ``pkg``, ``plugin`` and ``name``
(required, as in launch_ros), ``namespace``, ``if``/``unless``, and ``param``, ``remap`` and
``extra_arg`` (``name``, ``value``) children; an extra argument's value is typed as YAML.
A ``composable_lifecycle_node`` (newer than Jazzy: launch_ros 0.29.3, ros2/launch_ros#480)
takes the same plus ``autostart``; the lifecycle ones are loaded after the ``composable_node``
ones of the same parent, as upstream's parser lists them.
The composition modules are imported only when such a tag appears.
"""

from __future__ import annotations

from mlaunch.frontends.element import Element
from mlaunch.frontends.fields import Builder, as_key, pairs, required_text
from mlaunch.frontends.param_tags import parameter_item
from mlaunch.frontends.process_tags import node_kwargs
from mlaunch.launch.conditions.if_condition import IfCondition
from mlaunch.launch.conditions.unless_condition import UnlessCondition

TYPE_CHECKING = False  # mypy reads this as typing.TYPE_CHECKING; typing costs ~3 ms
if TYPE_CHECKING:
    from typing import Any


def _composable_node(e: Element, lifecycle: bool = False) -> Any:
    from mlaunch.launch_ros.descriptions.composable_lifecycle_node import ComposableLifecycleNode
    from mlaunch.launch_ros.descriptions.composable_node import ComposableNode

    kwargs: dict[str, Any] = {
        "package": required_text(e, "pkg"),
        "plugin": required_text(e, "plugin"),
        "name": required_text(e, "name"),
    }
    if lifecycle:
        autostart = e.flag("autostart")
        if autostart is not None:
            kwargs["autostart"] = autostart
    when = e.condition_text("if")
    unless = e.condition_text("unless")
    if when is not None and unless is not None:
        raise e.error("'if' and 'unless' cannot both be given", e.attrs["unless"])
    if when is not None:
        kwargs["condition"] = IfCondition(when)
    elif unless is not None:
        kwargs["condition"] = UnlessCondition(unless)
    namespace = e.text("namespace")
    if namespace is not None:
        kwargs["namespace"] = namespace
    parameters = [parameter_item(p) for p in e.subentities("param")]
    if parameters:
        kwargs["parameters"] = parameters
    remaps = pairs(e.subentities("remap"), "from", "to")
    if remaps:
        kwargs["remappings"] = remaps
    extra = [_extra_argument(x) for x in e.subentities("extra_arg")]
    if extra:
        kwargs["extra_arguments"] = extra
    e.finish()
    description = ComposableLifecycleNode(**kwargs) if lifecycle else ComposableNode(**kwargs)
    description.origin = e.origin  # type: ignore[attr-defined]
    return description


def _extra_argument(x: Element) -> dict[Any, Any]:
    """``{name: value}``; the value is a substitution, so it is typed as YAML (as launch_ros)."""
    from mlaunch.launch.substitution import TextSubstitution

    name = required_text(x, "name")
    value = required_text(x, "value")
    x.finish()
    return {as_key(name): TextSubstitution(text=value) if isinstance(value, str) else value}


def _descriptions(e: Element) -> list[Any]:
    plain = [_composable_node(c) for c in e.subentities("composable_node")]
    lifecycle = e.subentities("composable_lifecycle_node")
    return plain + [_composable_node(c, lifecycle=True) for c in lifecycle]


def _node_container(e: Element) -> Any:
    from mlaunch.launch_ros.actions.composable_node_container import ComposableNodeContainer

    kwargs = node_kwargs(e)
    for required in ("name", "namespace"):
        if required not in kwargs:
            raise e.error(f"missing required attribute {required!r} (a node_container needs it)")
    descriptions = _descriptions(e)
    if descriptions:
        kwargs["composable_node_descriptions"] = descriptions
    return ComposableNodeContainer(**kwargs)


def _load_composable_node(e: Element) -> Any:
    from mlaunch.launch_ros.actions.load_composable_nodes import LoadComposableNodes

    target = required_text(e, "target")
    return LoadComposableNodes(
        target_container=target, composable_node_descriptions=_descriptions(e)
    )


# The composition tags of the tag table (``mlaunch.frontends.tags.ACTIONS``).
COMPOSITION_TAGS: dict[str, Builder] = {
    "node_container": _node_container,
    "load_composable_node": _load_composable_node,
}
