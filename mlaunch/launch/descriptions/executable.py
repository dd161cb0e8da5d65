"""``Executable``: a program to run, described with substitutions, as launch.descriptions has it.

``prepare(context, action)`` performs the substitutions: ``final_cmd`` (the launch prefix
applied unless the prefix filter excludes the program), ``final_name`` (launch's ``name-N``
label, from the context's planner), ``final_cwd`` and ``final_env``.
"""

from __future__ import annotations

import os
import re
import shlex
from collections.abc import Iterable, Mapping
from typing import Any

from mlaunch.launch.substitution import Subs, normalize, perform_substitutions

Pairs = list[tuple[Subs, Subs]]


def _pairs(mapping: Mapping[Any, Any] | None) -> Pairs | None:
    if mapping is None:
        return None
    return [(normalize(key), normalize(value)) for key, value in mapping.items()]


def _perform_pairs(context: Any, pairs: Pairs, into: dict[str, str]) -> None:
    for key, value in pairs:
        into[perform_substitutions(context, key)] = perform_substitutions(context, value)


class Executable:
    """A command line with an optional name, folder and environment (see the module docstring)."""

    def __init__(
        self,
        *,
        cmd: Iterable[Any],
        prefix: Any = None,
        name: Any = None,
        cwd: Any = None,
        env: Mapping[Any, Any] | None = None,
        additional_env: Mapping[Any, Any] | None = None,
        arguments: Iterable[Any] | None = None,
    ) -> None:
        from mlaunch.launch.substitutions.launch_configuration import LaunchConfiguration

        if isinstance(cmd, str):
            cmd = [cmd]
        cmd = [*cmd, *(arguments or ())]
        # As written, for ExecuteLocal, which takes its process from a description.
        self.given: dict[str, Any] = {
            "cmd": cmd,
            "prefix": prefix,
            "name": name,
            "cwd": cwd,
            "env": env,
            "additional_env": additional_env,
        }
        self.cmd = [normalize(part) for part in cmd]
        self.arguments = arguments
        # Without a prefix of its own, the 'launch-prefix' configuration applies, filtered by
        # 'launch-prefix-filter'; a prefix given here always applies.
        self.prefix = normalize(
            LaunchConfiguration("launch-prefix", default="") if prefix is None else prefix
        )
        self.prefix_filter = (
            normalize(LaunchConfiguration("launch-prefix-filter", default=""))
            if prefix is None
            else None
        )
        self.name = None if name is None else normalize(name)
        self.cwd = None if cwd is None else normalize(cwd)
        self.env = _pairs(env)
        self.additional_env = _pairs(additional_env)
        self.final_cmd: list[str] | None = None
        self.final_name: str | None = None
        self.final_cwd: str | None = None
        self.final_env: dict[str, str] | None = None

    def _applies_prefix(self, context: Any, program: str) -> bool:
        if self.prefix_filter is None:
            return True
        pattern = perform_substitutions(context, self.prefix_filter)
        return re.match(pattern, os.path.basename(program)) is not None

    def prepare(self, context: Any, action: Any) -> None:
        """Perform every substitution with ``context`` (``action`` is for subclasses)."""
        cmd = [perform_substitutions(context, part) for part in self.cmd]
        if cmd and self._applies_prefix(context, cmd[0]):
            cmd = shlex.split(perform_substitutions(context, self.prefix)) + cmd
        self.final_cmd = cmd
        base = (
            os.path.basename(cmd[0])
            if self.name is None
            else perform_substitutions(context, self.name)
        )
        self.final_name = context.planner.new_label(base)
        self.final_cwd = None if self.cwd is None else perform_substitutions(context, self.cwd)
        env: dict[str, str] = {}
        if self.env is None:
            env.update(context.environment)
        else:
            _perform_pairs(context, self.env, env)
        if self.additional_env is not None:
            _perform_pairs(context, self.additional_env, env)
        self.final_env = env
