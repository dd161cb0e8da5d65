"""The launch-file spelling of machines: ``Machine``, ``PushMachine`` and ``machine=``.

They read like the rest of launch: ``Machine`` declares a computer (as DeclareLaunchArgument
declares an argument) and, with ``default=True``, makes it the machine of the nodes after it in
its scope; ``PushMachine`` does only the latter (as PushROSNamespace does for namespaces); a
``machine=`` keyword on a node or process names one for that process alone. Declarations are
global to the run, as ROS 1's ``<machine>`` tags were; the pushed machine is scoped like any
launch configuration, so a scoped GroupAction keeps it inside.
"""

from __future__ import annotations

from mlaunch.launch.action import Action
from mlaunch.launch.actions.execute_process import PUSHED_MACHINE as PUSHED
from mlaunch.launch.actions.execute_process import ROS1_DEFAULT_MACHINE
from mlaunch.launch.substitution import describe, normalize, perform_substitutions
from mlaunch.launch.substitutions.boolean_substitution import to_bool
from mlaunch.plan.errors import LaunchFileError
from mlaunch.plan.machine import DEFAULT_TIMEOUT, MachineSpec, check_name, declared, lookup

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext
    from mlaunch.launch.substitution import SomeSubstitutionsType


class Machine(Action):
    """Declare a computer that processes can run on (ROS 1's ``<machine>``).

    ``address`` is a host name, an address or an ssh ``Host`` alias; ``user`` and ``ssh_port``
    default to what the ssh configuration says; ``env_loader`` is a program on that computer
    that sets up the environment and runs its arguments (``/opt/ros/jazzy/env.sh``-style);
    ``timeout`` is how long to wait for the connection. ``default=True`` runs the nodes after it
    in this scope on this machine (ROS 1's ``default="true"``; ``"never"`` reads as false).
    """

    def __init__(
        self,
        *,
        name: SomeSubstitutionsType,
        address: SomeSubstitutionsType,
        user: SomeSubstitutionsType | None = None,
        ssh_port: Any = None,
        env_loader: SomeSubstitutionsType | None = None,
        default: Any = False,
        timeout: Any = DEFAULT_TIMEOUT,
        ros1_default: bool = False,
        **kwargs: Any,
    ) -> None:
        super().__init__(**kwargs)
        # roslaunch's <machine default="true"> (mlaunch.ros1.build): the default holds for the
        # nodes after it in the file's order, past its group, instead of in its scope.
        self.ros1_default = ros1_default
        self.name = normalize(name)
        self.address = normalize(address)
        self.user = None if user is None else normalize(user)
        self.ssh_port = ssh_port
        self.env_loader = None if env_loader is None else normalize(env_loader)
        self.default = default
        self.timeout = timeout

    def execute(self, context: LaunchContext) -> None:
        spec = self.resolve_spec(context)
        table = declared(context.run_state)
        known = table.get(spec.name)
        if known is not None and known._values()[:-1] != spec._values()[:-1]:
            raise LaunchFileError(
                f"machine {spec.name!r} is declared again with other settings"
                f" ({spec.describe()}; first: {known.describe()} at {known.origin or '?'})",
                where=self.origin,
            )
        table.setdefault(spec.name, spec)
        if _flag(context, self.default):
            if self.ros1_default:
                context.run_state[ROS1_DEFAULT_MACHINE] = spec.name
            else:
                context.launch_configurations[PUSHED] = spec.name

    def resolve_spec(self, context: LaunchContext) -> MachineSpec:
        planner = context.planner
        from mlaunch.plan.machine import is_local

        name = perform_substitutions(context, self.name)
        problem = check_name(name)
        if problem is not None:
            raise LaunchFileError(f"machine name {name!r} is invalid: {problem}", where=self.origin)
        address = perform_substitutions(context, self.address).strip()
        if not address or address.startswith("-") or any(c.isspace() for c in address):
            # A leading '-' would reach ssh as an option (-oProxyCommand=...), not a host.
            raise LaunchFileError(
                f"address of machine {name!r} is {address!r}; valid: a host name, an IP address"
                " or an ssh Host alias (no spaces, not starting with '-')",
                where=self.origin,
            )
        user = None if self.user is None else perform_substitutions(context, self.user) or None
        port = None
        if self.ssh_port is not None and str(self.ssh_port) != "":
            number = planner.float_value(self.ssh_port, "ssh_port", self.origin)
            if number != int(number) or not 0 < number < 65536:
                raise LaunchFileError(
                    f"ssh_port of machine {name!r} is {self.ssh_port!r};"
                    " valid: a port number from 1 to 65535",
                    where=self.origin,
                )
            port = int(number)
        loader = None
        if self.env_loader is not None:
            loader = perform_substitutions(context, self.env_loader) or None
        timeout = planner.float_value(self.timeout, "timeout", self.origin)
        if timeout <= 0:
            raise LaunchFileError(
                f"timeout of machine {name!r} is {timeout:g}; valid: seconds above 0",
                where=self.origin,
            )
        return MachineSpec(
            name=name,
            address=address,
            user=user,
            ssh_port=port,
            env_loader=loader,
            timeout=timeout,
            local=is_local(address, user),
            origin=self.origin,
        )

    def describe_short(self) -> str:
        return f"Machine(name={describe(self.name)}, address={describe(self.address)})"


class PushMachine(Action):
    """Run the nodes and processes after it, in this scope, on the machine named ``name``."""

    def __init__(self, name: SomeSubstitutionsType, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.name = normalize(name)

    def execute(self, context: LaunchContext) -> None:
        name = perform_substitutions(context, self.name)
        lookup(context.run_state, name, self.origin)
        context.launch_configurations[PUSHED] = name

    def describe_short(self) -> str:
        return f"PushMachine({describe(self.name)})"


def _flag(context: LaunchContext, value: Any) -> bool:
    if isinstance(value, bool):
        return value
    text = perform_substitutions(context, normalize(value)).strip().lower()
    if text == "never":
        return False
    return to_bool(text, "the machine's default")
