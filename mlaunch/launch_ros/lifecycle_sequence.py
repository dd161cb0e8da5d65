"""LifecycleSequence: managed nodes brought up in order, as declared in the launch file.

The launch-file side of lifecycle driving (mlaunch.parts.lifecycle runs it): the action, its plan
step, and the YAML/XML form, a ``mlaunch_lifecycle_sequence`` launch argument.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from mlaunch.launch.action import Action
from mlaunch.launch.substitution import SomeSubstitutionsType, normalize, perform_substitutions
from mlaunch.plan.errors import LaunchFileError
from mlaunch.plan.steps import LIFECYCLE, SEQUENCE_ARGUMENT, Note

if TYPE_CHECKING:
    from mlaunch.launch.launch_context import LaunchContext

# How long a node's lifecycle services may take to appear, and each transition to answer.
DEFAULT_TIMEOUT = 20.0
_NODE_PART = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")


# --- the launch-file side -----------------------------------------------------------------------


@dataclass
class SequenceStep(Note):
    """Plan step of a LifecycleSequence: the nodes' full names, in bring-up order (a Note: the
    lifecycle manager reads it from the plan)."""

    needs = LIFECYCLE  # the run attaches lifecycle driving (Plan.needs)

    origin: str = ""  # Step is a plain class: a dataclass subclass names its field itself
    nodes: tuple[str, ...] = ()
    shutdown_on_failure: bool = True
    timeout: float = DEFAULT_TIMEOUT

    def describe_data(self) -> dict[str, Any]:
        """--print --format json: the nodes in bring-up order and the sequence's settings."""
        return {
            "kind": "lifecycle_sequence",
            "nodes": list(self.nodes),
            "shutdown_on_failure": self.shutdown_on_failure,
            "timeout": self.timeout,
        }


class LifecycleSequence(Action):
    """Configure and activate lifecycle nodes in order, each once the previous one is active.

    ``nodes`` are node names: absolute (``/robot1/map_server``) or relative to the ROS namespace
    where the action stands. ``timeout`` bounds each node's wait for its services and each of its
    transitions. With ``shutdown_on_failure`` a failed transition ends the launch (status 1).
    """

    needs = LIFECYCLE  # seen in deferred bodies too (Plan.needs)

    def __init__(
        self,
        *,
        nodes: Iterable[SomeSubstitutionsType],
        shutdown_on_failure: bool = True,
        timeout: float | SomeSubstitutionsType = DEFAULT_TIMEOUT,
        **kwargs: Any,
    ) -> None:
        super().__init__(**kwargs)
        if isinstance(nodes, str):
            raise LaunchFileError(
                f"LifecycleSequence nodes={nodes!r} is a string; give a list of node names",
                where=self.origin,
            )
        self.nodes = [normalize(n) for n in nodes]
        self.shutdown_on_failure = shutdown_on_failure
        self.timeout = timeout

    def execute(self, context: LaunchContext) -> None:
        planner = context.planner
        namespace = str(context.launch_configurations.get("ros_namespace") or "/")
        names = [
            qualify(perform_substitutions(context, n), namespace, self.origin) for n in self.nodes
        ]
        check_sequence(names, self.origin)
        timeout = planner.float_value(self.timeout, "LifecycleSequence timeout", self.origin)
        if timeout <= 0:
            raise LaunchFileError(
                f"LifecycleSequence timeout is {timeout:g}; it must be > 0 seconds",
                where=self.origin,
            )
        planner.add(
            SequenceStep(
                origin=self.origin,
                nodes=tuple(names),
                shutdown_on_failure=bool(self.shutdown_on_failure),
                timeout=timeout,
            )
        )

    def describe_short(self) -> str:
        return f"LifecycleSequence({len(self.nodes)} nodes)"


def qualify(name: str, namespace: str, where: str) -> str:
    """The full name of a node named relative to ``namespace`` (or absolutely)."""
    name = name.strip()
    full = name if name.startswith("/") else f"{namespace.rstrip('/')}/{name}"
    parts = full[1:].split("/")
    if not name or not all(_NODE_PART.match(p) for p in parts):
        raise LaunchFileError(
            f"lifecycle node name {name!r} is not a ROS node name like 'map_server' or"
            " '/robot1/map_server' (letters, digits, '_'; not starting with a digit)",
            where=where,
        )
    return full


def check_sequence(names: list[str], where: str) -> None:
    if not names:
        raise LaunchFileError("LifecycleSequence needs at least one node", where=where)
    seen: set[str] = set()
    for name in names:
        if name in seen:
            raise LaunchFileError(f"LifecycleSequence lists {name!r} twice", where=where)
        seen.add(name)


def sequence_from_arguments(
    plan_arguments: Mapping[str, Any], given: Mapping[str, str]
) -> SequenceStep | None:
    """The YAML/XML form: the ``mlaunch_lifecycle_sequence`` launch argument, if declared."""
    info = plan_arguments.get(SEQUENCE_ARGUMENT)
    if info is None and SEQUENCE_ARGUMENT not in given:
        return None
    text = given.get(SEQUENCE_ARGUMENT, getattr(info, "default", None) or "")
    where = getattr(info, "origin", "") or "the command line"
    names = [qualify(n, "/", where) for n in re.split(r"[\s,]+", text) if n]
    if not names:
        return None
    check_sequence(names, where)
    return SequenceStep(origin=where, nodes=tuple(names))
