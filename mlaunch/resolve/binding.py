"""When the bodies of timers and event handlers take their values: when they fire, as launch does.

ros2 launch resolves a timer's or handler's actions against the launch state at the moment it
fires: a launch configuration, environment variable, ROS namespace, global parameter or remap set
later in the file applies (and a scoped group's values are gone by then). That is mlaunch's
default too, so files give the processes ros2 gives them.

mlaunch can instead resolve them with the values from where they were written (ROS 2's L#501,
a well-known complaint): ``--capture-at-definition`` on the command line, or a comment
``mlaunch: capture-at-definition`` anywhere in a launch file for the timers and handlers written
in that file (a comment, so the file still runs unchanged under ros2 launch). When a body fired
with launch's rule would resolve differently with the captured values, mlaunch warns with the
file:line of the timer or handler, saying what differs.
"""

from __future__ import annotations

from mlaunch.launch.launch_context import LaunchContext
from mlaunch.plan.pragmas import PRAGMA

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

# The launch configurations launch_ros keeps the pushed namespace, parameters and remaps in.
_ROS_STATE = {
    "ros_namespace": "the ROS namespace",
    "global_params": "the global parameters",
    "ros_remaps": "the global remaps",
}


class _Uses:
    """What a body reads from the launch state, found by walking its actions."""

    def __init__(self) -> None:
        self.configs: set[str] = set()
        self.env: set[str] = set()
        self.processes = False
        self.code = False


def _text(parts: Any) -> str | None:
    """The name a substitution list spells out without other substitutions, else None."""
    if isinstance(parts, str):
        return parts
    if not isinstance(parts, (list, tuple)):
        parts = [parts]
    texts = [p if isinstance(p, str) else getattr(p, "text", None) for p in parts]
    return "".join(str(t) for t in texts) if all(isinstance(t, str) for t in texts) else None


def _reads(entities: list[Any], uses: _Uses) -> None:
    """What the body reads: each entity the walk of the description meets (mlaunch.launch.walk),
    and the values it holds (substitutions, callbacks, entities the walk does not enter, such as
    a process's on_exit actions)."""
    from mlaunch.launch.walk import walk

    visits = list(walk(entities))
    walked = {id(v.entity) for v in visits}
    for visit in visits:
        walked.discard(id(visit.entity))  # scanned now; its own entities are scanned as met
        _walk(visit.entity, uses, walked)


def _walk(obj: Any, uses: _Uses, seen: set[int], depth: int = 0) -> None:
    if depth > 60 or id(obj) in seen or obj is None or isinstance(obj, (str, bytes, int, float)):
        return
    seen.add(id(obj))
    if isinstance(obj, (list, tuple, set, frozenset)):
        for item in obj:
            _walk(item, uses, seen, depth + 1)
        return
    if isinstance(obj, dict):
        for key, value in obj.items():
            _walk(key, uses, seen, depth + 1)
            _walk(value, uses, seen, depth + 1)
        return
    if callable(obj) and not hasattr(obj, "visit") and not hasattr(obj, "perform"):
        # launch-file code (OpaqueFunction's function, a handler lambda); mlaunch's own
        # callbacks (launch_testing's bookkeeping) read no launch configuration
        uses.code = uses.code or launch_file_code(obj)
        return
    module = type(obj).__module__
    if not module.startswith("mlaunch.") or isinstance(obj, LaunchContext):
        return
    from mlaunch.launch.actions.execute_process import ExecuteProcess
    from mlaunch.launch.substitutions.environment_variable import EnvironmentVariable
    from mlaunch.launch.substitutions.launch_configuration import LaunchConfiguration

    if isinstance(obj, LaunchConfiguration):
        name = _text(obj.variable_name)
        if name is not None:
            uses.configs.add(name)
    elif isinstance(obj, EnvironmentVariable):
        name = _text(obj.name)
        if name is not None:
            uses.env.add(name)
    elif isinstance(obj, ExecuteProcess):
        uses.processes = True
    fields = list(getattr(obj, "__dict__", {}).values())
    for cls in type(obj).__mro__:
        for slot in getattr(cls, "__slots__", ()):
            fields.append(getattr(obj, slot, None))
    for value in fields:
        _walk(value, uses, seen, depth + 1)


def differences(
    captured: LaunchContext, live: LaunchContext, entities: list[Any], callback: Any
) -> list[str]:
    """What the body would see differently with the values captured where it was written."""
    uses = _Uses()
    _reads(entities, uses)
    uses.code = uses.code or (callback is not None and launch_file_code(callback))
    then, now = captured.launch_configurations, live.launch_configurations
    out = []
    for name in sorted(uses.configs):
        if then.get(name) != now.get(name):
            out.append(
                f"launch configuration {name!r} is {_show(then.get(name))} where written,"
                f" {_show(now.get(name))} when it fires"
            )
    env_then, env_now = captured.environment, live.environment
    for name in sorted(uses.env):
        if env_then.get(name) != env_now.get(name):
            out.append(
                f"environment variable {name!r} is {_show(env_then.get(name))} where written,"
                f" {_show(env_now.get(name))} when it fires"
            )
    if uses.processes:
        for key, what in _ROS_STATE.items():
            if then.get(key) != now.get(key):
                out.append(f"{what} of its nodes differ")
        keys = set(env_then) | set(env_now)
        changed = sorted(k for k in keys if env_then.get(k) != env_now.get(k))
        if changed:
            out.append(f"its processes' environment differs ({', '.join(changed[:5])})")
    if uses.code and not out and (then != now or env_then != env_now):
        out.append("the launch-file code in it sees other launch configurations or environment")
    return out


def launch_file_code(fn: Any) -> bool:
    """Whether ``fn`` is code of the user's (a launch file's function or lambda), not mlaunch's
    own or a builtin: only such code can read launch configurations when it fires."""
    from mlaunch.plan.origin import is_mlaunch_file

    for _ in range(10):  # partials of bound methods of partials ...
        inner = getattr(fn, "func", None) or getattr(fn, "__func__", None)
        if inner is None:
            break
        fn = inner
    code = getattr(fn, "__code__", None)
    if code is not None:
        return not is_mlaunch_file(code.co_filename)
    # A callable object: where its class is written (a builtin's module has no file).
    import sys

    filename = getattr(sys.modules.get(type(fn).__module__), "__file__", None)
    return isinstance(filename, str) and not is_mlaunch_file(filename)


def _show(value: Any) -> str:
    return "unset" if value is None else repr(value)


_WARNED: set[int] = set()


def warn_once(
    captured: LaunchContext, origin: str, diffs: list[str], subject: str = ""
) -> str | None:
    """The warning for a body that resolves differently, once per timer or handler;
    ``subject`` says what the body does (its actions, or the function it calls)."""
    if not diffs or id(captured) in _WARNED:
        return None
    _WARNED.add(id(captured))  # captured lives as long as its Deferred: the id stays unique
    what = f"{subject}: " if subject else ""
    return (
        f"{origin}: {what}resolved when it fires, as ros2 launch does, and {'; '.join(diffs)}"
        f" (--capture-at-definition, or a comment '{PRAGMA}' in the file, uses the values"
        " from where it was written)"
    )
