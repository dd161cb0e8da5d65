"""``launch.actions.execute_process``: ``ExecuteProcess``, a process to start, as ROS 2's
describes it, resolved to a ProcessSpec for the supervisor.

The ROS layer's Node builds on ``process_spec``: it computes its own command line and adds what
the ROS side knows (the node's names, a stand-in, its params files).
"""

from __future__ import annotations

import os

from mlaunch.launch.action import Action
from mlaunch.launch.substitution import (
    Substitution,
    describe,
    normalize,
    perform,
    perform_substitutions,
)
from mlaunch.launch.substitutions.boolean_substitution import to_bool
from mlaunch.launch.substitutions.launch_configuration import LaunchConfiguration
from mlaunch.plan.errors import MlaunchError, SubstitutionFailure
from mlaunch.plan.steps import OUTPUT_MODES, SHARE, Deferred, ProcessSpec, RespawnPolicy

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Iterable, Mapping
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext
    from mlaunch.launch.substitution import SomeSubstitutionsType
    from mlaunch.plan.steps import NodeInfo


# The launch configuration PushMachine (or a default Machine) sets for the rest of its scope
# (mlaunch.machines); here so that a launch without machines never imports that package.
PUSHED_MACHINE = "mlaunch.machine"
# The run state's key for roslaunch's default machine: a <machine default="true"> gives its
# machine to the nodes after it in the file's order, past the end of its <group> or <include>
# (roslaunch's loader hands the default back up), not in a launch configuration's scope.
ROS1_DEFAULT_MACHINE = "ros1_default_machine"

_SIGTERM_DEFAULT = LaunchConfiguration("sigterm_timeout", default=5)
_SIGKILL_DEFAULT = LaunchConfiguration("sigkill_timeout", default=5)


def _number(context: LaunchContext, value: Any, what: str, origin: str) -> float:
    planner = context.planner
    return planner.float_value(value, what, origin)


class ExecuteProcess(Action):
    """A process to start and supervise, with ROS 2's keywords (ExecuteProcess/ExecuteLocal).

    mlaunch extensions: ``respawn`` also takes ``'always'``/``'on-failure'``; ``required=True``
    is short for ``on_exit=Shutdown()``; ``respawn_backoff``/``respawn_max_delay`` slow a crash
    loop down. The first restart waits ``respawn_delay`` as in ROS 2; each further exit within
    10 s of starting multiplies the wait by ``respawn_backoff`` (default 2, so a crash loop cannot
    burn a core), up to ``respawn_max_delay`` (30 s). ``respawn_backoff=1`` restarts like ROS 2.
    """

    completes_later = True  # ExecutionComplete when it exits for good (the engine says)
    # ROS 2's action, name, cmd, cwd and env of the process, as executing (or ``prepare``) made
    # them; None before. The pid comes when it starts (mlaunch.app.launch_service fills it in;
    # launch_testing looks processes up by it).
    process_details: dict[str, Any] | None = None
    # The exit status of its last run (negative: killed by that signal); None until it exits.
    return_code: int | None = None

    def __init__(
        self,
        *,
        cmd: Iterable[SomeSubstitutionsType],
        prefix: SomeSubstitutionsType | None = None,
        name: SomeSubstitutionsType | None = None,
        cwd: SomeSubstitutionsType | None = None,
        env: dict[Any, Any] | None = None,
        additional_env: dict[Any, Any] | None = None,
        shell: bool = False,
        sigterm_timeout: Any = None,
        sigkill_timeout: Any = None,
        emulate_tty: Any = False,
        output: Any = "log",
        output_format: str = "[{this.process_description.final_name}] {line}",
        cached_output: bool = False,
        log_cmd: bool = False,
        on_exit: Any = None,
        respawn: Any = False,
        respawn_delay: Any = None,
        respawn_max_retries: Any = -1,
        respawn_backoff: Any = 2.0,
        respawn_max_delay: Any = 30.0,
        required: Any = False,
        machine: SomeSubstitutionsType | None = None,
        **kwargs: Any,
    ) -> None:
        super().__init__(**kwargs)
        if isinstance(cmd, (str, Substitution)):
            cmd = [cmd]
        # As written, normalized as upstream's (substitution lists, (key, value) pairs of
        # them); the properties of the same names give the final values once prepared.
        self._cmd = [_subs(item) for item in cmd]
        self.prefix = None if prefix is None else _subs(prefix)
        self._name = None if name is None else _subs(name)
        # The label itself, not counted (a native ROS 1 node is labelled as roslaunch names
        # its process, whose number its __log:= file carries).
        self.exact_label: str | None = None
        self._cwd = None if cwd is None else _subs(cwd)
        self._env = _pairs(env)
        self.additional_env = _pairs(additional_env)
        self.shell = shell
        # ROS 2's defaults: the launch configurations sigterm_timeout/sigkill_timeout, else 5 s
        # (one substitution each, shared by every process, as upstream's default arguments).
        self.sigterm_timeout = (
            [_SIGTERM_DEFAULT] if sigterm_timeout is None else _subs(sigterm_timeout)
        )
        self.sigkill_timeout = (
            [_SIGKILL_DEFAULT] if sigkill_timeout is None else _subs(sigkill_timeout)
        )
        self.emulate_tty = emulate_tty
        # A dict of streams to destinations stays a dict, as upstream's.
        self.output = output if isinstance(output, dict) else _subs(output)
        self._process_description: Any = None
        self.log_cmd = log_cmd
        # Kept for launch_pytest.tools, which reads output only of processes that cache it.
        self.cached_output = cached_output
        self.on_exit = on_exit
        self.respawn = respawn
        self.respawn_delay = respawn_delay
        self.respawn_max_retries = respawn_max_retries
        self.respawn_backoff = respawn_backoff
        self.respawn_max_delay = respawn_max_delay
        self.required = required
        # mlaunch's: the name of a declared Machine to run on (mlaunch.machines).
        self.machine = None if machine is None else normalize(machine)

    @property
    def process_description(self) -> Any:
        """The process as upstream's ``Executable`` describes it (cmd, prefix, name, cwd, env),
        made when first asked (the first child's path does not import it)."""
        if self._process_description is None:
            from mlaunch.launch.descriptions.executable import Executable

            self._process_description = Executable(
                cmd=self._cmd,
                prefix=self.prefix,
                name=self._name,
                cwd=self._cwd,
                env=_mapping(self._env),
                additional_env=_mapping(self.additional_env),
            )
        return self._process_description

    @process_description.setter
    def process_description(self, description: Any) -> None:
        self._process_description = description

    # Upstream's getters: the final value once executed (or prepared), else as written.

    @property
    def name(self) -> Any:
        return self._name if self.process_details is None else self.process_details["name"]

    @property
    def cmd(self) -> Any:
        return self._cmd if self.process_details is None else self.process_details["cmd"]

    @property
    def cwd(self) -> Any:
        return self._cwd if self.process_details is None else self.process_details["cwd"]

    @property
    def env(self) -> Any:
        return self._env if self.process_details is None else self.process_details["env"]

    def command(self, context: LaunchContext) -> list[str]:
        """The argv before any prefix: each cmd item performed to one element."""
        return [perform_substitutions(context, item) for item in self._cmd]

    def execute(self, context: LaunchContext) -> None:
        context.planner.spawn(self._prepared(context))

    def prepare(self, context: LaunchContext) -> None:
        """Work out the process for ``context`` (substitutions, the launch prefix and its
        filter, the name with launch's number) into ``process_details``, as upstream's; it
        starts nothing. Executing prepares again, so the number counts on, as in launch."""
        self._prepared(context)

    def _prepared(self, context: LaunchContext) -> ProcessSpec:
        spec = self.build_spec(context)
        self.process_details = {
            "action": self,
            "name": spec.label,
            "cmd": list(spec.argv),
            "cwd": spec.cwd,
            "env": dict(spec.env),
        }
        return spec

    def build_spec(self, context: LaunchContext) -> ProcessSpec:
        machine = self._machine(context)
        return self.process_spec(context, self.command(context), machine=machine)

    def process_spec(
        self,
        context: LaunchContext,
        argv: list[str],
        *,
        node: NodeInfo | None = None,
        replaced_label: str | None = None,
        standin: str | None = None,
        temp_files: tuple[str, ...] = (),
        machine: Any = None,
    ) -> ProcessSpec:
        """The ProcessSpec for ``argv`` (before any prefix), with what the ROS layer adds.

        ``replaced_label`` labels a process whose argv is already a stand-in's (a Node whose
        package is not installed) as the program it replaces, unless a name or prefix leads;
        ``standin`` names what it replaces, ``temp_files`` what to remove after it;
        ``machine`` is the MachineSpec it runs on (None: no machine given or pushed).
        """
        planner = context.planner
        elsewhere = False
        if SHARE in context.run_state:  # --machine NAME: this run starts one machine's share
            from mlaunch.plan.machine import placed

            machine, elsewhere = placed(context.run_state[SHARE], machine)
        # Another computer's programs are found there (the ssh agent's lookup, or its share's run)
        remote = elsewhere or (machine is not None and not machine.local)
        if not argv or not argv[0]:
            raise SubstitutionFailure("the command is empty", where=self.origin)
        named = argv
        located = None
        if not remote:
            argv, located = planner.locate_program(argv, shell=self.shell, origin=self.origin)
        prefix = self._prefix(context, named)
        # The label comes from the program the launch file named, not from its stand-in.
        if self._name is not None:
            base = perform_substitutions(context, self._name)
        elif replaced_label is not None and not prefix:
            base = replaced_label
        else:
            base = os.path.basename((prefix or named)[0])
        env = self._environment(context)
        on_exit, required = self._exit_policy(context)
        spec = ProcessSpec(
            label=self.exact_label or planner.new_label(base),
            argv=tuple(prefix + argv),
            launch_prefix=tuple(prefix),
            env=env,
            env_changes=_env_changes(context.initial_environment, env),
            cwd=None if self._cwd is None else perform_substitutions(context, self._cwd),
            shell=self.shell,
            emulate_tty=self._emulate_tty(context),
            output=self._output(context),
            respawn=self._respawn(context),
            sigterm_timeout=_number(context, self.sigterm_timeout, "sigterm_timeout", self.origin),
            sigkill_timeout=_number(context, self.sigkill_timeout, "sigkill_timeout", self.origin),
            required=required,
            on_exit=on_exit,
            origin=self.origin,
            action=self,
            node=node,
            standin=standin if standin is not None else located,
            machine=machine,
        )
        if temp_files:
            spec.temp_files = (*spec.temp_files, *temp_files)
        if not remote and spec.cwd is not None and not os.path.isdir(spec.cwd):
            raise MlaunchError(
                f"working directory {spec.cwd!r} does not exist", where=self.origin, what=base
            )
        return spec

    def _runs_there(self, context: LaunchContext, machine: Any) -> bool:
        """Whether this process's program is another computer's, found there: its machine is
        reached over ssh, or (--machine) it is another machine's share, not started here."""
        if SHARE in context.run_state:
            from mlaunch.plan.machine import placed

            machine, elsewhere = placed(context.run_state[SHARE], machine)
            if elsewhere:
                return True
        return machine is not None and not machine.local

    # A roslaunch <node>/<executable> (mlaunch.ros1.build): given no machine, it takes the
    # file's default machine in roslaunch's order (ROS1_DEFAULT_MACHINE).
    follows_ros1_default = False

    def _machine(self, context: LaunchContext) -> Any:
        """The MachineSpec this process runs on, or None (no machine given or pushed)."""
        pushed = context.launch_configurations.get(PUSHED_MACHINE)
        if not pushed and self.follows_ros1_default:
            pushed = context.run_state.get(ROS1_DEFAULT_MACHINE)
        if self.machine is None and not pushed:
            return None  # the common case: nothing of mlaunch.machines is imported
        from mlaunch.plan.machine import lookup

        name = pushed if self.machine is None else perform_substitutions(context, self.machine)
        return lookup(context.run_state, str(name), self.origin) if name else None

    def _prefix(self, ctx: LaunchContext, argv: list[str]) -> list[str]:
        if self.prefix is not None:
            text = perform_substitutions(ctx, self.prefix)
        else:
            text = str(ctx.launch_configurations.get("launch-prefix", ""))
            pattern = str(ctx.launch_configurations.get("launch-prefix-filter", ""))
            if text and pattern:
                import re

                if not re.match(pattern, os.path.basename(argv[0])):
                    text = ""
        if not text.strip():
            return []
        import shlex

        return shlex.split(text)

    def _environment(self, ctx: LaunchContext) -> dict[str, str]:
        if self._env is not None:
            env = {perform(ctx, k): perform(ctx, v) for k, v in _items(self._env)}
        else:
            env = dict(ctx.environment)
        if self.additional_env:
            env.update({perform(ctx, k): perform(ctx, v) for k, v in _items(self.additional_env)})
        # Timely output from pipes (ROS 2's L#188): children line-buffer unless told otherwise.
        # Jazzy's rcutils reads RCUTILS_LOGGING_BUFFERED_STREAM (1 = line buffered) and warns
        # about the older RCUTILS_CONSOLE_STDOUT_LINE_BUFFERED, so only the new one is set.
        env.setdefault("PYTHONUNBUFFERED", "1")
        env.setdefault("RCUTILS_LOGGING_BUFFERED_STREAM", "1")
        return env

    def _emulate_tty(self, ctx: LaunchContext) -> bool:
        """Whether the child's stdout and stderr are pseudo-terminals, as launch gives them."""
        return _truthy(ctx, self.emulate_tty) or _truthy(
            ctx, ctx.launch_configurations.get("emulate_tty", False)
        )

    def _output(self, ctx: LaunchContext) -> str:
        override = ctx.environment.get("OVERRIDE_LAUNCH_PROCESS_OUTPUT")
        value = self.output
        text = override or (
            _output_from_dict(value) if isinstance(value, dict) else perform(ctx, value)
        )
        if text not in OUTPUT_MODES:
            raise MlaunchError(
                f"output is {text!r}; valid: {', '.join(OUTPUT_MODES)}", where=self.origin
            )
        return text

    def _respawn(self, context: LaunchContext) -> RespawnPolicy:
        planner = context.planner
        value = self.respawn
        if isinstance(value, bool):
            mode = "always" if value else "never"
        else:
            text = perform(context, value).strip().lower()
            if text in ("always", "on-failure", "on_failure", "never"):
                mode = text.replace("_", "-")
            else:
                try:
                    mode = "always" if to_bool(text, "respawn") else "never"
                except SubstitutionFailure:
                    raise MlaunchError(
                        f"respawn is {text!r}; valid: true, false, always, on-failure, never",
                        where=self.origin,
                    )
        delay = 0.0
        if self.respawn_delay is not None:
            delay = planner.float_value(self.respawn_delay, "respawn_delay", self.origin)
        retries = int(
            planner.float_value(self.respawn_max_retries, "respawn_max_retries", self.origin)
        )
        backoff = planner.float_value(self.respawn_backoff, "respawn_backoff", self.origin)
        max_delay = planner.float_value(self.respawn_max_delay, "respawn_max_delay", self.origin)
        if delay < 0 or backoff < 1.0:
            raise MlaunchError(
                f"respawn_delay must be >= 0 and respawn_backoff >= 1 (got {delay}, {backoff})",
                where=self.origin,
            )
        return RespawnPolicy(
            mode=mode, delay=delay, max_retries=retries, backoff=backoff, max_delay=max_delay
        )

    def _exit_policy(self, context: LaunchContext) -> tuple[Deferred | None, bool]:
        planner = context.planner
        required = self.required
        if not isinstance(required, bool):
            required = to_bool(perform(context, required), "required")
        on_exit = self.on_exit
        if on_exit is None:
            return None, required
        if callable(on_exit) and not hasattr(on_exit, "visit"):
            return planner.defer([], self.origin, callback=on_exit), required
        entities = list(on_exit) if isinstance(on_exit, (list, tuple)) else [on_exit]
        # launch.actions imports this module (ExecuteProcess is one of its names), so Shutdown
        # is looked up when an on_exit needs it rather than at import.
        from mlaunch.launch.actions.shutdown_action import Shutdown

        if any(isinstance(e, Shutdown) for e in entities):
            required = True
        return planner.defer(entities, self.origin), required

    def get_sub_entities(self) -> list[Any]:
        """The ``on_exit`` actions when they are a list (what introspection walks into)."""
        return list(self.on_exit) if isinstance(self.on_exit, list) else []

    @classmethod
    def _parse_cmdline(cls, cmd: str, parser: Any) -> list[Any]:
        """A markup command line as argv items, each a list of substitutions (what the parse
        methods of exposed process tags call, as upstream's)."""
        from mlaunch.launch.frontend.cmdline import parse_cmdline

        return parse_cmdline(cmd, parser)

    def describe_short(self) -> str:
        return "ExecuteProcess(" + " ".join(describe(c) for c in self._cmd) + ")"


def _items(mapping: Any) -> list[tuple[Any, Any]]:
    if isinstance(mapping, dict):
        return list(mapping.items())
    return list(mapping)


def _subs(value: Any) -> list[Substitution]:
    """``value`` as upstream's normalized list of substitutions; a number (mlaunch reads YAML
    numbers where launch wants text) as its text."""
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        value = str(value)
    return list(normalize(value))


def _mapping(pairs: list[tuple[list[Any], list[Any]]] | None) -> dict[Any, Any] | None:
    """Normalized pairs back as the mapping an ``Executable`` takes (keys made hashable)."""
    return None if pairs is None else {tuple(key): value for key, value in pairs}


def _pairs(mapping: Any) -> list[tuple[list[Substitution], list[Substitution]]] | None:
    """An environment mapping (or pairs) as upstream's list of (name, value) substitution
    lists; None stays None."""
    if mapping is None:
        return None
    return [(_subs(key), _subs(value)) for key, value in _items(mapping)]


def _truthy(ctx: LaunchContext, value: Any) -> bool:
    if isinstance(value, bool):
        return value
    try:
        return to_bool(perform(ctx, value), "emulate_tty")
    except SubstitutionFailure:
        return False


def _output_from_dict(value: dict[str, Any]) -> str:
    """ROS 2's dict form of ``output``, mapped to the nearest whole mode."""
    targets = {k: ({v} if isinstance(v, str) else set(v)) for k, v in value.items()}
    both = targets.get("both", set())
    stdout = targets.get("stdout", set()) | both
    stderr = targets.get("stderr", set()) | both
    if "screen" in stdout and "screen" in stderr:
        return "both" if ("log" in stdout or "log" in stderr) else "screen"
    if "own_log" in stdout or "own_log" in stderr:
        return "own_log"
    return "log"


def _env_changes(before: dict[str, str], after: dict[str, str]) -> dict[str, str | None]:
    changes: dict[str, str | None] = {k: v for k, v in after.items() if before.get(k) != v}
    changes.update({k: None for k in before if k not in after})
    return changes


def which(name: str, env: Mapping[str, str]) -> str | None:
    from mlaunch.launch.substitutions.find_executable import which as which_on_path

    return which_on_path(name, env.get("PATH", os.defpath))
