"""ROS scope state and naming rules: what PushROSNamespace, SetParameter and SetRemap leave for
the nodes after them, and rmw's rules for node names and namespaces (launch_ros.utilities).

The state lives in the launch configurations under ROS 2's keys: ``ros_namespace`` (str),
``global_params`` (``(name, value)`` pairs and params-file paths) and ``ros_remaps`` (``(from,
to)`` pairs). Both are lists extended in place, as in launch_ros, so a SetParameter,
SetParametersFromFile or SetRemap inside a scoped GroupAction also applies after the group
when the list already existed outside it (launch's shallow-copied scope): mlaunch warns where
that happens. ``--scoped-parameters`` (or a comment ``mlaunch: scoped-parameters`` in the file)
keeps them inside the group: an immutable tuple that each action replaces.

Nothing here imports rclpy: names and namespaces are validated with rmw's rules, re-stated.
"""

from __future__ import annotations

import re

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext


# --- names and namespaces (launch_ros.utilities, rmw's validation rules) -----------------------


def make_namespace_absolute(ns: str) -> str:
    return ns if ns.startswith("/") else "/" + ns


def prefix_namespace(base_ns: str | None, ns: str | None) -> str | None:
    """``ns`` under ``base_ns`` when relative; absolute ``ns`` wins; trailing '/' stripped.

    None when both are None; otherwise absolute (launch_ros's ``return_absolute_ns=True``).
    """
    if base_ns is None and ns is None:
        return None
    if ns is None:
        combined = base_ns or ""
    elif not base_ns or ns.startswith("/"):
        combined = ns
    else:
        combined = ("" if base_ns == "/" else base_ns) + "/" + ns
    if combined != "/":
        combined = combined.rstrip("/")
    return make_namespace_absolute(combined)


NAMESPACE_MAX_LENGTH = 245
NODE_NAME_MAX_LENGTH = 255
_NAME_CHARS = re.compile(r"[A-Za-z0-9_]*")
_NAMESPACE_CHARS = re.compile(r"[A-Za-z0-9_/]*")


def node_name_problem(name: str) -> str | None:
    """Why rmw would reject a node name, or None."""
    if not name:
        return "node name must not be empty"
    if not _NAME_CHARS.fullmatch(name):
        return "node name must not contain characters other than alphanumerics or '_'"
    if name[0].isdigit():
        return "node name must not start with a number"
    if len(name) > NODE_NAME_MAX_LENGTH:
        return f"node name length should not exceed {NODE_NAME_MAX_LENGTH}"
    return None


def namespace_problem(ns: str) -> str | None:
    """Why rmw would reject an (absolute) namespace, or None."""
    if not ns:
        return "namespace must not be empty"
    if not ns.startswith("/"):
        return "namespace must be absolute, it must lead with a '/'"
    if len(ns) > 1 and ns.endswith("/"):
        return "namespace must not end with a '/', unless only a '/'"
    if not _NAMESPACE_CHARS.fullmatch(ns):
        return "namespace must not contain characters other than alphanumerics, '_', or '/'"
    if "//" in ns:
        return "namespace must not contain repeated '/'"
    if any(token[:1].isdigit() for token in ns.split("/")):
        return "namespace must not have a token that starts with a number"
    if len(ns) > NAMESPACE_MAX_LENGTH:
        return f"namespace should not exceed {NAMESPACE_MAX_LENGTH} characters"
    return None


# --- scope state --------------------------------------------------------------------------------


def global_params(context: LaunchContext) -> tuple[Any, ...]:
    return tuple(context.launch_configurations.get("global_params") or ())


def add_global_params(context: LaunchContext, action: Any, entries: tuple[Any, ...]) -> None:
    """Extend the global parameters as launch_ros does, or within the scope on request (the
    option, the file's comment, or ``keep_in_scope`` on the action: ROS 1 files' params)."""
    _extend_shared(context, action, "global_params", entries, "global parameter")


def add_global_remap(context: LaunchContext, action: Any, rule: tuple[str, str]) -> None:
    """Add a global remap rule as launch_ros's SetRemap does: its list is extended in place too,
    so inside a scoped group it reaches the nodes after the group (the same opt-in keeps it in)."""
    _extend_shared(context, action, "ros_remaps", (rule,), "global remap")


def _extend_shared(
    context: LaunchContext, action: Any, key: str, entries: tuple[Any, ...], what: str
) -> None:
    # A stand-in context of a unit test (launch_configurations only) plans nothing: no options.
    planner = getattr(context, "planner", None)
    from mlaunch.plan.pragmas import SCOPED_PARAMETERS, file_has

    configs = context.launch_configurations
    current = configs.get(key)
    origin = action.origin or ""
    scoped = getattr(action, "keep_in_scope", False) or (
        planner is not None and planner.options.scoped_parameters
    )
    if scoped or file_has(origin, SCOPED_PARAMETERS):
        configs[key] = (*(current or ()), *entries)
    elif isinstance(current, list):
        if planner is not None and context.shared_with_outer_scope(current):
            planner.warn(
                f"{origin}: this {what} also applies to the nodes after the enclosing"
                " group, as in ros2 launch (its list is shared with the outer scope);"
                " --scoped-parameters, or a comment 'mlaunch: scoped-parameters' in the file,"
                " keeps it inside the group"
            )
        current.extend(entries)
    else:
        configs[key] = [*(current or ()), *entries]


# The context globals' table of where each SetParametersFromFile file was given.
PARAMS_FILE_ORIGINS_KEY = "mlaunch_params_file_origins"


def note_params_file_origin(context: Any, filename: str, origin: str | None) -> None:
    """Remember where a SetParametersFromFile gave ``filename``: a node that cannot find the
    file names that line (the file is looked for when a node uses it, as in launch_ros)."""
    if not origin or not hasattr(context, "extend_globals"):
        return  # a stand-in context of a unit test
    origins: dict[str, str] | None = context.locals.get(PARAMS_FILE_ORIGINS_KEY)
    if origins is None:
        origins = {}
        context.extend_globals({PARAMS_FILE_ORIGINS_KEY: origins})
    origins.setdefault(filename, origin)


def params_file_origin(context: Any, filename: str) -> str:
    """`` (given by SetParametersFromFile at FILE:LINE)``, or nothing when unknown."""
    locals_ = getattr(context, "locals", None)
    origins = None if locals_ is None else locals_.get(PARAMS_FILE_ORIGINS_KEY)
    origin = None if origins is None else origins.get(filename)
    return f" (given by SetParametersFromFile at {origin})" if origin else ""


def ros_remaps(context: LaunchContext) -> tuple[tuple[str, str], ...]:
    return tuple(context.launch_configurations.get("ros_remaps") or ())


__all__ = [
    "add_global_params",
    "add_global_remap",
    "global_params",
    "make_namespace_absolute",
    "namespace_problem",
    "node_name_problem",
    "note_params_file_origin",
    "params_file_origin",
    "prefix_namespace",
    "ros_remaps",
]
