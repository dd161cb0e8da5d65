"""How deep a launch tree may nest, and the include chain that finds include cycles.

Launch trees are walked recursively (building entities, resolving them). Python's default
recursion limit (1000 frames) ends such a walk at ~240 nested groups with a bare
RecursionError; ROS 2 itself runs ~190 nested XML groups and ~500 nested Python ones. mlaunch
raises the interpreter's limit once (``allow_deep_trees``) so that every walk fits
``DEPTH_LIMIT`` levels, and each frontend and the resolver stop at ``DEPTH_LIMIT`` with an error
naming the file and line where the limit was passed.
"""

from __future__ import annotations

import os
import sys

from mlaunch.plan.errors import LaunchFileError

TYPE_CHECKING = False  # mypy reads this as typing.TYPE_CHECKING; typing costs ~3 ms
if TYPE_CHECKING:
    from mlaunch.launch.launch_context import LaunchContext

# Nesting levels of groups, timers and includes a launch tree may have (ROS 2: ~190 in XML).
DEPTH_LIMIT = 1000
# Frames the interpreter allows: each nesting level of the deepest walk costs up to ~20 frames.
# Pure Python frames do not use the C stack in Python 3.11+, so this is safe.
_RECURSION_LIMIT = 25 * DEPTH_LIMIT


def allow_deep_trees() -> None:
    """Let the recursive walks of a launch tree reach ``DEPTH_LIMIT`` levels."""
    if sys.getrecursionlimit() < _RECURSION_LIMIT:
        sys.setrecursionlimit(_RECURSION_LIMIT)


def too_deep(
    where: str | None, what: str, limit: int = DEPTH_LIMIT, includes: IncludeChain | None = None
) -> LaunchFileError:
    """The error for a tree nested past ``limit`` levels at ``where`` (inside ``includes``)."""
    inside = ""
    if includes is not None and includes.entries:
        path, origin, _, _ = includes.entries[-1]
        inside = (
            f" ({len(includes.entries)} includes deep, the innermost of {_name(path)}"
            f" at {_name(origin)})"
        )
    return LaunchFileError(
        f"{what} nest deeper than {limit} levels, mlaunch's limit{inside}; flatten the launch"
        " file (an include or group inside itself, or generated nesting?)",
        where=where,
    )


class IncludeChain:
    """The includes being resolved, outermost first, to report a cycle instead of recursing.

    Including a file again is fine when something changed (a recursion that ends on an
    argument); including it again with the same launch configurations and environment as where
    it is already being included can only repeat forever, so that is an error naming the chain.
    """

    __slots__ = ("entries",)

    def __init__(self) -> None:
        # (included file, origin of the include, configurations, environment)
        self.entries: list[tuple[str, str, dict[str, object], dict[str, str]]] = []

    def enter(self, path: str, origin: str | None, context: LaunchContext) -> _Entered:
        """Record the include of ``path`` (a ``with`` block) or raise if it closes a cycle."""
        return self.enter_state(
            path, origin, dict(context.launch_configurations), dict(context.environment)
        )

    def enter_state(
        self, path: str, origin: str | None, configs: dict[str, object], environment: dict[str, str]
    ) -> _Entered:
        """``enter`` for a reader whose state is not a LaunchContext (roslaunch's args, ns)."""
        here = origin or "?"
        for index, (seen, _, seen_configs, seen_env) in enumerate(self.entries):
            if seen == path and seen_configs == configs and seen_env == environment:
                raise self.cycle_error(index, path, here)
        self.entries.append((path, here, configs, environment))
        return _Entered(self)

    def cycle_error(self, start: int, path: str, origin: str) -> LaunchFileError:
        steps = [f"{_name(p)} (included at {_name(o)})" for p, o, _, _ in self.entries[start:]]
        steps.append(f"{_name(path)} again (included at {_name(origin)})")
        return LaunchFileError(
            f"include cycle: {' -> '.join(steps)}, with the same arguments each time, so it"
            " would never end; break the cycle or give the include an argument that ends it",
            where=origin,
        )


class _Entered:
    """``with chain.enter(...)``: leaves the include on exit (a class: contextlib costs ~0.7 ms)."""

    __slots__ = ("chain",)

    def __init__(self, chain: IncludeChain) -> None:
        self.chain = chain

    def __enter__(self) -> None:
        return None

    def __exit__(self, *exc_info: object) -> None:
        self.chain.entries.pop()


def _name(location: str) -> str:
    """A path or ``path:line`` as its file name (and line): chains stay readable."""
    return os.path.basename(location)
