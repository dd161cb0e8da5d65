"""``launch.substitutions.anon_name``: a name made unique for this launch."""

from __future__ import annotations

import os

from mlaunch.launch.substitution import (
    SomeSubstitutionsType,
    Substitution,
    describe,
    normalize,
    perform_substitutions,
)

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from mlaunch.launch.launch_context import LaunchContext


class AnonName(Substitution):
    """A name made unique per launch: ``<name>_<host>_<pid>_<random>``, cached per name."""

    def __init__(self, name: SomeSubstitutionsType) -> None:
        self.name = normalize(name)

    def perform(self, context: LaunchContext) -> str:
        name = perform_substitutions(context, self.name)
        key = "anon" + name
        cached = context.launch_configurations.get(key)
        if isinstance(cached, str):
            return cached
        from mlaunch.plan.inputs import volatile

        volatile(f"$(anon {name}) is a new name in every run")
        unique = int.from_bytes(os.urandom(8), "big") >> 1
        raw = f"{name}_{os.uname().nodename}_{os.getpid()}_{unique}"
        value = raw.replace(".", "_").replace("-", "_").replace(":", "_")
        context.launch_configurations[key] = value
        return value

    def describe(self) -> str:
        return f"AnonName({describe(self.name)})"
