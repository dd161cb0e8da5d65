"""A resolved Plan as systemd units: one service per process, all wanted by one target.

What maps, and how:
- argv, env, working directory: ``ExecStart`` (quoted for systemd: ``%`` and ``$`` escaped),
  ``EnvironmentFile`` (the environment mlaunch resolved with, minus the login session's
  variables) plus ``Environment``/``UnsetEnvironment`` for what the launch file changed, and
  ``WorkingDirectory`` (the process's ``cwd``, else where the export ran, as a launch would);
- params files: copied next to the units and named by their installed path;
- respawn: ``Restart=always|on-failure`` with ``RestartSec=respawn_delay`` and no start limit
  (ROS 2 restarts without end); retries and crash-loop backoff have no systemd 252 equivalent;
- stop: ``KillMode=control-group``, ``KillSignal=SIGINT`` (the ladder's first step) and
  ``TimeoutStopSec`` = sigterm_timeout + sigkill_timeout before systemd's SIGKILL;
- required processes: the target ``BindsTo`` them, so their end stops the whole launch;
- ordering: a process started by ``OnProcessStart(target)`` is ``After=`` its target; one started
  by ``OnProcessExit(target)`` is ``After=``/``Requires=`` it, and the target becomes a
  ``Type=oneshot`` service (started means exited); a ``TimerAction`` delay becomes
  ``ExecStartPre=/bin/sleep``.
Anything that cannot be exported (handlers that call Python, lifecycle events, other machines)
is a warning in the README and on stderr, never silently dropped.
"""

from __future__ import annotations

import os
import re
import shlex
import shutil

from mlaunch.plan.errors import MlaunchError
from mlaunch.plan.steps import AddHandler, Deferred, Plan, ProcessSpec, Spawn, StartTimer, Step

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable, Mapping

# Variables of a login session that mean nothing to a service.
SESSION_VARIABLES = frozenset(
    {"TERM", "SHELL", "PWD", "OLDPWD", "SHLVL", "_", "LS_COLORS", "MAIL", "DISPLAY", "COLORTERM",
     "WAYLAND_DISPLAY", "DBUS_SESSION_BUS_ADDRESS", "TMUX", "TMUX_PANE", "STY", "WINDOW",
     "SSH_AUTH_SOCK", "SSH_AGENT_PID", "SSH_CLIENT", "SSH_CONNECTION", "SSH_TTY", "TERM_PROGRAM",
     "TERM_PROGRAM_VERSION", "VTE_VERSION", "HISTFILE", "PS1", "PROMPT_COMMAND", "EDITOR",
     "OVERRIDE_LAUNCH_PROCESS_OUTPUT"}
)  # fmt: skip
SESSION_PREFIXES = ("XDG_", "SSH_", "GPG_", "MLAUNCH_", "PYTEST_", "KONSOLE_", "GNOME_", "VSCODE_")
UNIT_CHARS = re.compile(r"[^A-Za-z0-9:_.\-]")


class Unit:
    """One service being written: its process, its ordering and its extra lines."""

    def __init__(self, spec: ProcessSpec, name: str) -> None:
        self.spec = spec
        self.name = name
        self.after: list[str] = []
        self.requires: list[str] = []
        self.delay = 0.0
        self.oneshot = False


class Export:
    """The units of one plan, built by walking its steps (and the handlers' and timers')."""

    def __init__(
        self,
        plan: Plan,
        *,
        prefix: str,
        expand: Callable[[Deferred], Plan | None],
    ) -> None:
        self.plan = plan
        self.prefix = prefix
        self.expand = expand
        self.units: list[Unit] = []
        self.warnings: list[str] = list(plan.warnings)
        self.pending: list[tuple[AddHandler, list[str], list[str], float]] = []

    def build(self) -> list[Unit]:
        """Every process's unit; handlers are looked at once every process they may target is."""
        self.walk(self.plan.steps, after=[], requires=[], delay=0.0)
        while self.pending:
            step, after, requires, delay = self.pending.pop(0)
            self.handler(step, after, requires, delay)
        return self.units

    def walk(
        self, steps: list[Step], *, after: list[str], requires: list[str], delay: float
    ) -> None:
        for step in steps:
            if isinstance(step, Spawn) and step.spec is not None:
                self.add(step.spec, after, requires, delay)
            elif isinstance(step, StartTimer) and step.body is not None:
                body = self.expand(step.body)
                if body is not None:
                    self.walk(body.steps, after=after, requires=requires, delay=delay + step.period)
            elif isinstance(step, AddHandler):
                self.pending.append((step, after, requires, delay))

    def add(self, spec: ProcessSpec, after: list[str], requires: list[str], delay: float) -> None:
        if spec.machine is not None and not spec.machine.local:
            self.warnings.append(
                f"{spec.label} runs on machine {spec.machine.name!r}: exported to run on the"
                " computer the units are installed on"
            )
        if spec.node is not None and spec.node.lifecycle and spec.node.autostart:
            self.warnings.append(
                f"{spec.label} is a lifecycle node with autostart: nothing drives it to active"
                " under systemd (mlaunch does that when it runs the launch)"
            )
        unit = Unit(spec, unit_name(f"{self.prefix}-{spec.label}") + ".service")
        unit.after, unit.requires, unit.delay = list(after), list(requires), delay
        self.units.append(unit)

    def handler(
        self, step: AddHandler, after: list[str], requires: list[str], delay: float
    ) -> None:
        where = step.origin or "?"
        if step.kind == "shutdown":
            return  # the target's stop is the launch's shutdown; what runs then is not a unit
        if step.kind not in ("process_start", "process_exit") or step.body is None:
            self.warnings.append(f"{where}: a {step.kind} handler is not exported")
            return
        if step.matcher is None:
            self.warnings.append(f"{where}: a handler for any process is not exported")
            return
        targets = [u for u in self.units if step.matcher(u.spec)]
        if not targets:
            self.warnings.append(f"{where}: a {step.kind} handler matches no exported process")
            return
        body = self.expand(step.body)
        if body is None:
            return
        names = [u.name for u in targets]
        if step.kind == "process_exit":
            for unit in targets:
                unit.oneshot = True
            self.walk(body.steps, after=after + names, requires=requires + names, delay=delay)
        else:
            self.walk(body.steps, after=after + names, requires=requires, delay=delay)


def unit_name(text: str) -> str:
    return UNIT_CHARS.sub("_", text)


def quote_exec(word: str) -> str:
    """One ExecStart argument: specifiers and variables escaped, quoted when needed."""
    word = word.replace("%", "%%").replace("$", "$$")
    if word and not re.search(r"[\s\"'\\;]", word):
        return word
    escaped = word.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n")
    return f'"{escaped.replace(chr(9), chr(92) + "t")}"'


def quote_assignment(name: str, value: str) -> str:
    """One ``Environment=`` item, ``"NAME=value"`` with systemd's escapes."""
    text = f"{name}={value}".replace("%", "%%")
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n") + '"'


def environment_file(env: Mapping[str, str]) -> str:
    """The shared EnvironmentFile: the resolved environment without the session's variables."""
    lines = []
    for name in sorted(env):
        if name in SESSION_VARIABLES or name.startswith(SESSION_PREFIXES):
            continue
        if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", name):
            continue
        value = env[name].replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n")
        lines.append(f'{name}="{value}"')
    return "\n".join(lines) + "\n"


def exec_start(spec: ProcessSpec, path: str) -> list[str]:
    """The argv a service runs: the shell's for shell=True, argv[0] made absolute."""
    if spec.shell:
        return ["/bin/sh", "-c", " ".join(spec.argv)]
    argv = list(spec.argv)
    if not os.path.isabs(argv[0]):
        found = shutil.which(argv[0], path=path)
        if found is None:
            raise MlaunchError(
                f"{spec.label}: program {argv[0]!r} is not on the PATH the units get ({path})"
            )
        argv[0] = found
    return argv


def service_text(unit: Unit, *, target: str, env_file: str, cwd: str, user: str | None) -> str:
    spec = unit.spec
    argv = exec_start(spec, spec.env.get("PATH", os.defpath))
    lines = [
        "[Unit]",
        f"Description={spec.label} of {os.path.basename(spec.origin.split(':')[0]) or 'launch'}"
        " (mlaunch export)",
        f"PartOf={target}",
    ]
    if unit.after:
        lines.append("After=" + " ".join(unit.after))
    if unit.requires:
        lines.append("Requires=" + " ".join(unit.requires))
    if spec.respawn.mode != "never":
        lines.append("StartLimitIntervalSec=0")
    lines += ["", "[Service]"]
    if unit.oneshot:
        lines += ["Type=oneshot", "RemainAfterExit=yes"]
    else:
        lines.append("Type=exec")
    if user:
        lines.append(f"User={user}")
    if unit.delay > 0:
        lines.append(f"ExecStartPre=/bin/sleep {unit.delay:g}")
    lines.append("ExecStart=" + " ".join(quote_exec(w) for w in argv))
    lines.append(f"WorkingDirectory={spec.cwd or cwd}")
    lines.append(f"EnvironmentFile={env_file}")
    changed = {k: v for k, v in sorted(spec.env_changes.items()) if v is not None}
    if changed:
        lines.append("Environment=" + " ".join(quote_assignment(k, v) for k, v in changed.items()))
    unset = sorted(k for k, v in spec.env_changes.items() if v is None)
    if unset:
        lines.append("UnsetEnvironment=" + " ".join(unset))
    lines += restart_lines(spec)
    lines += [
        "KillMode=control-group",
        "KillSignal=SIGINT",
        f"TimeoutStopSec={spec.sigterm_timeout + spec.sigkill_timeout:g}",
        f"SyslogIdentifier={spec.label}",
    ]
    return "\n".join(lines) + "\n"


def restart_lines(spec: ProcessSpec) -> list[str]:
    mode = spec.respawn.mode
    if mode == "never":
        return ["Restart=no"]
    restart = "always" if mode == "always" else "on-failure"
    return [f"Restart={restart}", f"RestartSec={spec.respawn.delay:g}"]


def target_text(units: list[Unit], description: str) -> str:
    lines = ["[Unit]", f"Description={description} (mlaunch export)"]
    if units:
        lines.append("Wants=" + " ".join(u.name for u in units))
    required = [u.name for u in units if u.spec.required]
    if required:
        lines.append("BindsTo=" + " ".join(required))
    lines += ["", "[Install]", "WantedBy=multi-user.target"]
    return "\n".join(lines) + "\n"


def install_params(units: list[Unit], out_dir: str, install_dir: str) -> None:
    """Copy each process's params files next to the units and point its argv at the copies."""
    params = os.path.join(out_dir, "params")
    for unit in units:
        spec = unit.spec
        argv = list(spec.argv)
        count = 0
        for i in range(1, len(argv)):
            if argv[i - 1] != "--params-file" or not os.path.isfile(argv[i]):
                continue
            os.makedirs(params, exist_ok=True)
            name = f"{unit.name.removesuffix('.service')}-{count}.yaml"
            shutil.copyfile(argv[i], os.path.join(params, name))
            argv[i] = os.path.join(install_dir, "params", name)
            count += 1
        spec.argv = tuple(argv)


def readme_text(prefix: str, install_dir: str, source: str, warnings: list[str]) -> str:
    lines = [
        f"# {prefix}: systemd units of {source}",
        "",
        "Written by `mlaunch export`: one service per process, all wanted by"
        f" `{prefix}.target`. Install and start them (units stay in {install_dir}):",
        "",
        f"    sudo systemctl link {shlex.quote(install_dir)}/*.service"
        f" {shlex.quote(install_dir)}/{prefix}.target"
        f" && sudo systemctl enable --now {prefix}.target",
        "",
        f"Stop everything with `sudo systemctl stop {prefix}.target`; follow the output with"
        f" `journalctl -f -u '{prefix}-*'`.",
    ]
    if warnings:
        lines += ["", "## Warnings", ""] + [f"- {w}" for w in warnings]
    return "\n".join(lines) + "\n"
