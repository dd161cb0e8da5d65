"""``launch_ros.descriptions``: what a launch file describes a node's parts with.

The parameter types live in ``parameter_descriptions``; ``ComposableNode`` lives with the
composition code and loads only when a file names it, so a launch without composable nodes does
not pay for it.
"""

from __future__ import annotations

from mlaunch.launch_ros.parameter_descriptions import Parameter, ParameterFile, ParameterValue

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.launch_ros.composable import ComposableNode


def __getattr__(name: str) -> type[ComposableNode]:
    if name == "ComposableNode":
        from mlaunch.launch_ros.composable import ComposableNode

        return ComposableNode
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = [
    "ComposableNode",
    "Parameter",
    "ParameterFile",
    "ParameterValue",
]
