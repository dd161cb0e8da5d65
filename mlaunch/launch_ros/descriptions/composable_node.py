"""``launch_ros.descriptions.composable_node``: ``ComposableNode``, a component to load into a
container.

Data only: what to load (package, plugin), its names, parameters, remappings, the container's
extra arguments and a condition, each normalized when the description is built (as launch_ros
does), so a bad parameters list fails at the line that wrote it. The request made of it is built
in ``mlaunch.launch_ros.load_request``; the actions that load it are
``launch_ros.actions.composable_node_container`` and ``load_composable_nodes``.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping

from mlaunch.launch.substitution import normalize
from mlaunch.plan.errors import LaunchFileError, LaunchFileTypeError
from mlaunch.plan.steps import COMPONENTS, LIFECYCLE, NO_NEEDS, Need

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.substitution import Substitution

    Subs = tuple[Substitution, ...]


class ComposableNode:
    """A component: a plugin of a package, loaded into a container by LoadNode."""

    def __init__(
        self,
        *,
        package: Any,
        plugin: Any,
        name: Any = None,
        namespace: Any = None,
        parameters: Any = None,
        remappings: Any = None,
        extra_arguments: Any = None,
        condition: Any = None,
    ) -> None:
        from mlaunch.launch_ros.params import normalize_parameters

        self.package = normalize(package)
        self.node_plugin = normalize(plugin)
        self.node_name = None if name is None else normalize(name)
        self.node_namespace = None if namespace is None else normalize(namespace)
        self.parameters = None if parameters is None else normalize_parameters(parameters)
        # launch_ros keeps an empty list of remappings / extra arguments as "none given".
        self.remappings = remap_rules(remappings) if remappings else None
        self.extra_arguments = normalize_parameters(extra_arguments) if extra_arguments else None
        self._condition = condition

    def condition(self) -> Any:
        """The condition (launch_ros exposes it as a method, not a property)."""
        return self._condition

    def describe_short(self) -> str:
        from mlaunch.launch.substitution import describe

        text = f"ComposableNode(package={describe(self.package)}"
        text += f", plugin={describe(self.node_plugin)}"
        if self.node_name is not None:
            text += f", name={describe(self.node_name)}"
        return text + ")"


def remap_rules(remappings: Any) -> list[tuple[Subs, Subs]]:
    """``[(from, to), ...]`` or a dict, each side normalized to substitutions (Node's too)."""
    if remappings is None:
        return []
    if isinstance(remappings, (str, Mapping)) or not isinstance(remappings, Iterable):
        raise LaunchFileTypeError(
            f"remappings must be a list of (from, to) tuples, got {type(remappings).__name__}:"
            f" {remappings!r:.80} (write remappings=[('from', 'to'), ...])"
        )
    rules = []
    for item in remappings:
        if not isinstance(item, tuple) or len(item) != 2:
            raise LaunchFileTypeError(
                f"a remapping must be a (from, to) pair, a tuple, got {item!r:.80}"
                " (write remappings=[('from', 'to'), ...])"
            )
        rules.append((normalize(item[0]), normalize(item[1])))
    return rules


def load_needs(descriptions: Iterable[ComposableNode]) -> frozenset[Need]:
    """What loading ``descriptions`` needs attached to the run: the LoadNode driver, and
    lifecycle driving when one may autostart (a ComposableLifecycleNode whose autostart is
    True or substitutions)."""
    found = list(descriptions)
    if not found:
        return NO_NEEDS
    if any(getattr(d, "autostart", False) is not False for d in found):
        return COMPONENTS | LIFECYCLE
    return COMPONENTS


def composable_nodes(descriptions: Any) -> list[ComposableNode]:
    if descriptions is None:
        return []
    if isinstance(descriptions, (str, ComposableNode)) or not hasattr(descriptions, "__iter__"):
        raise LaunchFileError(
            "composable_node_descriptions must be a list of ComposableNode, got"
            f" {type(descriptions).__name__}: {descriptions!r:.80}"
        )
    out = list(descriptions)
    for d in out:
        if not isinstance(d, ComposableNode):
            raise LaunchFileError(
                "composable_node_descriptions must hold ComposableNode descriptions"
                f" (launch_ros.descriptions.ComposableNode), got {type(d).__name__}: {d!r:.80}"
            )
    return out
