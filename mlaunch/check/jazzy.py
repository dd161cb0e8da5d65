"""What ROS 2 Jazzy's launch frontends accept (launch 3.4.3, launch_ros 0.26.6), as data.

The portability check (``mlaunch FILE --check``) holds YAML and XML launch files to this table:
each tag Jazzy exposes, the attributes its parser reads and the type it reads them with, the
sub-entities it takes, and the ``$(...)`` substitutions it knows. Written from reading the Jazzy
sources' ``parse()`` methods; tests/test_portability.py checks the tag and substitution names
against the reference where it is built.

Types: ``text`` is read as a string (a YAML number or boolean there is a TypeError in Jazzy),
``cmdline`` is text split by Jazzy's command-line rule, ``bool``/``int``/``float`` accept that
YAML type or text, ``any`` is a param value, ``entities:NAME`` a list of sub-entities of kind
NAME, ``xml-only`` text that only launch_xml reads (its ``NAME-sep`` list separators).
"""

from __future__ import annotations

_COMMON = {"if": "text", "unless": "text"}

_PROCESS = {
    **_COMMON,
    "cwd": "text",
    "name": "text",
    "on_exit": "on_exit",
    "launch-prefix": "text",
    "output": "text",
    "respawn": "respawn",
    "respawn_max_retries": "int",
    "respawn_delay": "float",
    "sigkill_timeout": "float",
    "sigterm_timeout": "float",
    "shell": "bool",
    "emulate_tty": "bool",
    "env": "entities:env",
}

_NODE = {
    **_PROCESS,
    "args": "cmdline",
    "ros_args": "cmdline",
    "node-name": "text",
    "exec_name": "text",
    "pkg": "text",
    "exec": "text",
    "namespace": "text",
    "remap": "entities:remap",
    "param": "entities:param",
}

# Action tags: attribute -> type. Children (actions) only where TAKES_ACTIONS says so.
ACTIONS: dict[str, dict[str, str]] = {
    "executable": {**_PROCESS, "cmd": "cmdline"},
    "node": _NODE,
    "node_container": {**_NODE, "composable_node": "entities:composable_node"},
    "load_composable_node": {
        **_COMMON,
        "target": "text",
        "composable_node": "entities:composable_node",
    },
    "arg": {
        **_COMMON,
        "name": "text",
        "default": "text",
        "description": "text",
        "choice": "entities:choice",
    },
    "log": {**_COMMON, "message": "text"},
    "let": {**_COMMON, "name": "text", "value": "text"},
    "set_env": {**_COMMON, "name": "text", "value": "text"},
    "unset_env": {**_COMMON, "name": "text"},
    "append_env": {
        **_COMMON,
        "name": "text",
        "value": "text",
        "prepend": "bool",
        "separator": "text",
    },
    "reset_env": {**_COMMON},
    "reset": {**_COMMON, "keep": "entities:keep"},
    "include": {**_COMMON, "file": "text", "arg": "entities:arg"},
    "group": {**_COMMON, "scoped": "bool", "forwarding": "bool", "keep": "entities:keep"},
    "timer": {**_COMMON, "period": "float", "cancel_on_shutdown": "bool"},
    "ros_timer": {**_COMMON, "period": "float"},
    "shutdown": {**_COMMON, "reason": "text"},
    "set_parameter": {**_COMMON, "name": "text", "value": "text"},
    "set_parameters_from_file": {**_COMMON, "filename": "text"},
    "set_remap": {**_COMMON, "from": "text", "to": "text"},
    "set_ros_log_dir": {**_COMMON, "new_log_dir": "text"},
    "set_use_sim_time": {**_COMMON, "value": "text"},
    "push_ros_namespace": {**_COMMON, "namespace": "text"},
    "push-ros-namespace": {**_COMMON, "namespace": "text"},
}

TAKES_ACTIONS = ("launch", "group", "timer", "ros_timer")

# Sub-entities: kind -> attribute -> type.
SUBENTITIES: dict[str, dict[str, str]] = {
    "env": {"name": "text", "value": "text"},
    "remap": {"from": "text", "to": "text"},
    "param": {
        "name": "text",
        "value": "any",
        "value-sep": "xml-only",
        "type": "text",
        "param": "entities:param",
        "from": "text",
        "allow_substs": "bool",
    },
    "choice": {"value": "text"},
    "keep": {"name": "text", "value": "text"},
    "arg": {"name": "text", "value": "text"},
    "extra_arg": {"name": "text", "value": "text"},
    "composable_node": {
        **_COMMON,
        "pkg": "text",
        "plugin": "text",
        "name": "text",
        "namespace": "text",
        "param": "entities:param",
        "remap": "entities:remap",
        "extra_arg": "entities:extra_arg",
    },
}

ROOT = {"deprecated": "text"}

SUBSTITUTIONS = (
    "all",
    "and",
    "anon",
    "any",
    "command",
    "dirname",
    "env",
    "equals",
    "eval",
    "exec-in-pkg",
    "file-content",
    "filename",
    "find-exec",
    "find-pkg-prefix",
    "find-pkg-share",
    "if",
    "launch_log_dir",
    "log_dir",
    "not",
    "not-equals",
    "or",
    "param",
    "var",
)

# Registered in Jazzy but failing there (observed under the reference): name -> what happens.
BROKEN_ACTIONS = {
    "set_use_sim_time": "its frontend passes text where it wants a boolean, so it fails when run"
    " (\"Type 'Type.BOOL' and value ... do not agree\"; fixed in launch_ros 0.29.3, Rolling,"
    " ros2/launch_ros#488); use set_parameter use_sim_time",
}
BROKEN_SUBSTITUTIONS = {
    "any": "its parser passes the arguments wrongly, so the file fails to load",
    "all": "its parser passes the arguments wrongly, so the file fails to load",
}

# on_exit: the only value Jazzy's frontends accept.
ON_EXIT_WORDS = ("shutdown",)

# Newer than Jazzy, and run by mlaunch on Jazzy (--check names the release that has each): a
# Jazzy ros2 launch rejects the file. Tags, substitutions, and Python names and modules.
_LAUNCH_3_8 = "launch 3.8 (Kilted, ros2/launch#802)"
_COMPOSABLE_LIFECYCLE = "launch_ros 0.29.3 (Rolling, ros2/launch_ros#480)"
NEWER_TAGS = {
    "for_each": _LAUNCH_3_8,
    "for": _LAUNCH_3_8,
    "lifecycle_node": "launch_ros after 0.29.3 (Rolling, ros2/launch_ros#482)",
}
# Sub-entities newer than Jazzy (inside node_container, load_composable_node).
NEWER_SUBENTITIES = {
    "composable_lifecycle_node": _COMPOSABLE_LIFECYCLE,
}
NEWER_SUBSTITUTIONS = {
    "for-var": _LAUNCH_3_8,
    "index": _LAUNCH_3_8,
    "string-join": "launch 3.9.5 (Rolling, ros2/launch#857)",
}
_STRING_JOIN = "launch 3.8.1 (Kilted, ros2/launch#843)"
NEWER_PYTHON = {
    "launch.actions.ForEach": _LAUNCH_3_8,
    "launch.actions.ForLoop": _LAUNCH_3_8,
    "launch.actions.for_loop": _LAUNCH_3_8,
    "launch.substitutions.ForEachVar": _LAUNCH_3_8,
    "launch.substitutions.ForLoopIndex": _LAUNCH_3_8,
    "launch.substitutions.for_loop_var": _LAUNCH_3_8,
    "launch.substitutions.StringJoinSubstitution": _STRING_JOIN,
    "launch.substitutions.string_join_substitution": _STRING_JOIN,
    "launch_ros.descriptions.ComposableLifecycleNode": _COMPOSABLE_LIFECYCLE,
    "launch_ros.descriptions.composable_lifecycle_node": _COMPOSABLE_LIFECYCLE,
}


def newer(what: str, release: str) -> str:
    """The finding for syntax newer than Jazzy, which mlaunch runs."""
    return (
        f"{what} is newer than Jazzy: {release} has it, ros2 launch (Jazzy) fails on it;"
        " mlaunch runs it"
    )
