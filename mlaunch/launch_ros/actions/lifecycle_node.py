"""``launch_ros.actions.lifecycle_node``: a managed node, driven through its transitions by the
run's lifecycle part.
"""

from __future__ import annotations

from mlaunch.launch.substitution import (
    SomeSubstitutionsType,
)
from mlaunch.launch_ros.actions.node import Node
from mlaunch.plan.steps import LIFECYCLE

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any


class LifecycleNode(Node):
    """A managed node: name and namespace are required; ``autostart`` configures and activates
    it once it is up (driving the transitions is the supervisor's lifecycle support)."""

    is_lifecycle = True
    needs = LIFECYCLE  # the run attaches lifecycle driving (Plan.needs)

    def __init__(
        self,
        *,
        name: SomeSubstitutionsType,
        namespace: SomeSubstitutionsType,
        autostart: bool = False,
        **kwargs: Any,
    ) -> None:
        super().__init__(name=name, namespace=namespace, **kwargs)
        self.autostart = autostart
