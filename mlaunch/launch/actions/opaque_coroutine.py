"""``launch.actions.opaque_coroutine``: not supported (no asyncio loop runs launch code), said
as a located error.
"""

from __future__ import annotations

from mlaunch.launch.actions.opaque_function import OpaqueFunction
from mlaunch.plan.errors import LaunchFileError
from mlaunch.plan.origin import caller_origin

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable
    from typing import Any


class OpaqueCoroutine(OpaqueFunction):
    """Not supported: mlaunch does not run an asyncio loop for launch files."""

    def __init__(self, *, coroutine: Callable[..., Any], **kwargs: Any) -> None:
        raise LaunchFileError(
            "OpaqueCoroutine is not supported by mlaunch (no asyncio loop runs launch code);"
            " use an OpaqueFunction or a TimerAction",
            where=caller_origin(),
        )
