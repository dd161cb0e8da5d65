"""``launch.substitutions``: lazily evaluated pieces of text, with the names and semantics of ROS 2
launch.

A substitution is data until ``perform(context)`` is called while resolving; ``describe()``
shows it unresolved (``--print`` of deferred actions, ``--show-args`` defaults). Each lives in
its own module, named as upstream's; the base class and the helpers (``normalize``, ``perform``
...) are ``launch.substitution``'s. This package only gathers the names
(``mlaunch.launch.gathering``), mlaunch's helpers too, as it always served them.
"""

from __future__ import annotations

from mlaunch.launch.gathering import Gathered

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.launch.substitution import (
        Path,
        SomeSubstitutionsType,
        SomeSubstitutionsType_types_tuple,
        Subs,
        Substitution,
        TextSubstitution,
        describe,
        is_substitution_like,
        normalize,
        perform,
        perform_substitutions,
    )
    from mlaunch.launch.substitutions.anon_name import AnonName
    from mlaunch.launch.substitutions.boolean_substitution import (
        AllSubstitution,
        AndSubstitution,
        AnySubstitution,
        NotSubstitution,
        OrSubstitution,
        evaluate_condition_expression,
        to_bool,
    )
    from mlaunch.launch.substitutions.command import Command
    from mlaunch.launch.substitutions.environment_variable import EnvironmentVariable
    from mlaunch.launch.substitutions.equals_substitution import EqualsSubstitution
    from mlaunch.launch.substitutions.file_content import FileContent
    from mlaunch.launch.substitutions.find_executable import FindExecutable
    from mlaunch.launch.substitutions.for_loop_var import ForEachVar, ForLoopIndex
    from mlaunch.launch.substitutions.if_else_substitution import IfElseSubstitution
    from mlaunch.launch.substitutions.launch_configuration import LaunchConfiguration
    from mlaunch.launch.substitutions.launch_log_dir import LaunchLogDir
    from mlaunch.launch.substitutions.local_substitution import LocalSubstitution
    from mlaunch.launch.substitutions.not_equals_substitution import NotEqualsSubstitution
    from mlaunch.launch.substitutions.path_join_substitution import (
        PathJoinSubstitution,
        PathSubstitution,
    )
    from mlaunch.launch.substitutions.python_expression import PythonExpression
    from mlaunch.launch.substitutions.string_join_substitution import StringJoinSubstitution
    from mlaunch.launch.substitutions.this_launch_file import ThisLaunchFile
    from mlaunch.launch.substitutions.this_launch_file_dir import ThisLaunchFileDir
    from mlaunch.plan.errors import SubstitutionFailure

_gathered = Gathered(
    globals(),
    {
        "ForEachVar": ".for_loop_var",
        "ForLoopIndex": ".for_loop_var",
        "StringJoinSubstitution": ".string_join_substitution",
        "AllSubstitution": ".boolean_substitution",
        "AndSubstitution": ".boolean_substitution",
        "AnonName": ".anon_name",
        "AnySubstitution": ".boolean_substitution",
        "Command": ".command",
        "EnvironmentVariable": ".environment_variable",
        "EqualsSubstitution": ".equals_substitution",
        "FileContent": ".file_content",
        "FindExecutable": ".find_executable",
        "IfElseSubstitution": ".if_else_substitution",
        "LaunchConfiguration": ".launch_configuration",
        "LaunchLogDir": ".launch_log_dir",
        "LocalSubstitution": ".local_substitution",
        "NotEqualsSubstitution": ".not_equals_substitution",
        "NotSubstitution": ".boolean_substitution",
        "OrSubstitution": ".boolean_substitution",
        "Path": "mlaunch.launch.substitution",
        "PathJoinSubstitution": ".path_join_substitution",
        "PathSubstitution": ".path_join_substitution",
        "PythonExpression": ".python_expression",
        "SomeSubstitutionsType": "mlaunch.launch.substitution",
        "SomeSubstitutionsType_types_tuple": "mlaunch.launch.substitution",
        "Subs": "mlaunch.launch.substitution",
        "Substitution": "mlaunch.launch.substitution",
        "SubstitutionFailure": "mlaunch.plan.errors",
        "TextSubstitution": "mlaunch.launch.substitution",
        "ThisLaunchFile": ".this_launch_file",
        "ThisLaunchFileDir": ".this_launch_file_dir",
        "describe": "mlaunch.launch.substitution",
        "evaluate_condition_expression": ".boolean_substitution",
        "is_substitution_like": "mlaunch.launch.substitution",
        "normalize": "mlaunch.launch.substitution",
        "perform": "mlaunch.launch.substitution",
        "perform_substitutions": "mlaunch.launch.substitution",
        "to_bool": ".boolean_substitution",
    },
    submodules=(
        "for_loop_var",
        "string_join_substitution",
        "anon_name",
        "boolean_substitution",
        "command",
        "environment_variable",
        "equals_substitution",
        "file_content",
        "find_executable",
        "if_else_substitution",
        "launch_configuration",
        "launch_log_dir",
        "local_substitution",
        "not_equals_substitution",
        "path_join_substitution",
        "python_expression",
        "substitution_failure",
        "text_substitution",
        "this_launch_file",
        "this_launch_file_dir",
    ),
)
__getattr__ = _gathered.attribute
__dir__ = _gathered.listing


__all__ = [
    "AllSubstitution",
    "AndSubstitution",
    "AnonName",
    "AnySubstitution",
    "Command",
    "EnvironmentVariable",
    "EqualsSubstitution",
    "FileContent",
    "FindExecutable",
    "ForEachVar",
    "ForLoopIndex",
    "IfElseSubstitution",
    "LaunchConfiguration",
    "LaunchLogDir",
    "LocalSubstitution",
    "NotEqualsSubstitution",
    "NotSubstitution",
    "OrSubstitution",
    "Path",
    "PathJoinSubstitution",
    "PathSubstitution",
    "PythonExpression",
    "SomeSubstitutionsType",
    "SomeSubstitutionsType_types_tuple",
    "StringJoinSubstitution",
    "Subs",
    "Substitution",
    "SubstitutionFailure",
    "TextSubstitution",
    "ThisLaunchFile",
    "ThisLaunchFileDir",
    "describe",
    "evaluate_condition_expression",
    "is_substitution_like",
    "normalize",
    "perform",
    "perform_substitutions",
    "to_bool",
]
