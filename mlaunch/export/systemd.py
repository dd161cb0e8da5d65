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

import fnmatch
import os
import re
import shlex
import shutil

from mlaunch.plan.errors import MlaunchError
from mlaunch.plan.steps import AddHandler, Deferred, Plan, ProcessSpec, Spawn, StartTimer, Step

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable, Mapping

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
        if len(unit.name) > 255:
            raise UnsafeValue(
                f"unit name {unit.name[:40]!r}... is {len(unit.name)} characters long;"
                " systemd takes at most 255 (a shorter --name or process name)"
            )
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


# Characters no unit-file line can hold as they are: a newline or carriage return ends the
# setting (and starts a directive of the writer's choosing), NUL ends the file's text.
UNSAFE = re.compile(r"[\x00-\x08\x0a-\x1f\x7f]")
C_ESCAPES = {"\\": "\\\\", '"': '\\"', "\n": "\\n", "\t": "\\t", "\r": "\\r"}


class UnsafeValue(MlaunchError):
    """A value that systemd would read differently from what the launch says: not exported."""


def why_unsafe(value: str) -> str | None:
    """What makes ``value`` impossible to write as the whole right side of a setting, or None."""
    bad = UNSAFE.search(value)
    if bad is not None:
        names = {"\n": "a newline", "\r": "a carriage return", "\x00": "a NUL byte"}
        return f"it holds {names.get(bad.group(), f'the control character {bad.group()!r}')}"
    if value.endswith("\\"):
        return "it ends with a backslash (systemd would join the next line to it)"
    if value != value.strip():
        return "it starts or ends with white space (systemd strips it)"
    return None


def setting(what: str, value: str) -> str:
    """``value`` as a plain setting (Description=, WorkingDirectory=, ...): specifiers escaped."""
    why = why_unsafe(value)
    if why is not None:
        raise UnsafeValue(f"{what} {value!r} cannot be written in a systemd unit: {why}")
    return value.replace("%", "%%")


def c_escape(text: str) -> str:
    """``text`` inside systemd's double quotes: backslash, quote and control characters escaped."""
    out = []
    for ch in text:
        if ch in C_ESCAPES:
            out.append(C_ESCAPES[ch])
        elif UNSAFE.match(ch):
            out.append(f"\\x{ord(ch):02x}")
        else:
            out.append(ch)
    return "".join(out)


def quote_exec(word: str) -> str:
    """One ExecStart argument: specifiers and variables escaped, quoted when needed."""
    word = word.replace("%", "%%").replace("$", "$$")
    if word and not re.search(r"[\s\"'\\;\x00-\x1f\x7f]", word):
        return word
    return f'"{c_escape(word)}"'


def quote_assignment(name: str, value: str) -> str:
    """One ``Environment=`` item, ``"NAME=value"`` with systemd's escapes."""
    check_variable(name, value)
    return '"' + c_escape(f"{name}={value}".replace("%", "%%")) + '"'


def check_variable(name: str, value: str) -> None:
    """Refuse a variable that an environment file or ``Environment=`` cannot hold as it is."""
    if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", name):
        raise UnsafeValue(
            f"environment variable name {name!r} cannot be written in a systemd unit:"
            " a name is letters, digits and '_', not starting with a digit"
        )
    bad = UNSAFE.search(value)
    if bad is not None:
        raise UnsafeValue(
            f"environment variable {name}={value!r} cannot be written in a systemd unit:"
            f" it holds the control character {bad.group()!r}"
        )


def environment_file(env: Mapping[str, str]) -> str:
    """An EnvironmentFile of exactly ``env`` (what the export was asked to carry)."""
    lines = ["# written by mlaunch export: what the launch and --env put in every unit"]
    for name in sorted(env):
        check_variable(name, env[name])
        value = re.sub(r'([\\"$`])', r"\\\1", env[name])
        lines.append(f'{name}="{value}"')
    return "\n".join(lines) + "\n"


def chosen_environment(patterns: list[str], environ: Mapping[str, str]) -> dict[str, str]:
    """The variables ``--env`` asks for: ``NAME=VALUE`` as given, ``NAME`` or a pattern from
    ``environ``; a NAME that is not set is an error (a unit would silently miss it)."""
    chosen: dict[str, str] = {}
    for pattern in patterns:
        name, eq, value = pattern.partition("=")
        if eq:
            chosen[name] = value
            continue
        found = {k: v for k, v in environ.items() if fnmatch.fnmatchcase(k, name)}
        if not found:
            raise UnsafeValue(f"--env {pattern!r}: no such variable in the environment")
        chosen.update(found)
    for name, value in chosen.items():
        check_variable(name, value)
    return chosen


def exec_start(spec: ProcessSpec, path: str, cwd: str) -> list[str]:
    """The argv a service runs: the shell's for shell=True, argv[0] made absolute.

    Absolute always, even when a relative PATH entry (``.``, an empty one) finds the program:
    systemd reads a leading ``-``, ``@``, ``+``, ``!`` or ``:`` of ExecStart as a prefix, so a
    program named ``-x`` found as ``-x`` would run ``x`` with its failure ignored.
    """
    if spec.shell:
        return ["/bin/sh", "-c", " ".join(spec.argv)]
    argv = list(spec.argv)
    if not os.path.isabs(argv[0]):
        # A relative PATH entry or program is relative to the folder the process starts in,
        # as the launch would have run it.
        base = spec.cwd or cwd
        search = os.pathsep.join(os.path.join(base, d) for d in path.split(os.pathsep))
        program = os.path.join(base, argv[0]) if os.sep in argv[0] else argv[0]
        found = shutil.which(program, path=search)
        if found is None:
            raise MlaunchError(
                f"{spec.label}: program {argv[0]!r} is not on the PATH the units get ({path})"
            )
        argv[0] = os.path.normpath(found)
    return argv


# systemd's time spans are microseconds in 64 bits; more is its "infinity"
LONGEST_SPAN = (2**64 - 2) / 1e6


def timespan(seconds: float, *, least: float = 0.0) -> str:
    """``seconds`` as a time span systemd reads (``RestartSec=``, ``TimeoutStopSec=``, sleep).

    ``:g`` wrote a million seconds as ``1e+06``, which systemd ignores with a warning (so the
    default applies), and a negative time as itself, refused as well. A time below ``least``
    (a negative one: launch acts at once) is ``least``; past what systemd counts, ``infinity``.
    """
    if seconds != seconds or seconds >= LONGEST_SPAN:  # NaN or too long
        return "infinity"
    seconds = max(seconds, least)
    text = f"{seconds:.6f}".rstrip("0").rstrip(".")
    return text or "0"


def service_text(unit: Unit, *, target: str, env_file: str, cwd: str, user: str | None) -> str:
    """The ``.service`` file of one process; a value systemd would misread is an UnsafeValue."""
    spec = unit.spec
    argv = exec_start(spec, spec.env.get("PATH", os.defpath), cwd)
    source = os.path.basename(spec.origin.split(":")[0]) or "launch"
    lines = [
        "[Unit]",
        "Description=" + setting("process name", f"{spec.label} of {source} (mlaunch export)"),
        f"PartOf={target}",
    ]
    if unit.after:
        lines.append("After=" + " ".join(unit.after))
    if unit.requires:
        lines.append("Requires=" + " ".join(unit.requires))
    if spec.respawn.mode != "never":
        lines.append("StartLimitIntervalSec=0")
    lines += ["", "[Service]"]
    lines += ["Type=oneshot", "RemainAfterExit=yes"] if unit.oneshot else ["Type=exec"]
    if user:
        lines.append("User=" + user_setting(user))
    if unit.delay > 0:
        lines.append(f"ExecStartPre=/bin/sleep {timespan(unit.delay)}")
        # the start timeout (90 s by default) covers ExecStartPre: the wait must fit in it
        lines.append(f"TimeoutStartSec={timespan(unit.delay + 90)}")
    lines.append("ExecStart=" + " ".join(quote_exec(w) for w in argv))
    lines.append("WorkingDirectory=" + setting("working directory", spec.cwd or cwd))
    lines.append("EnvironmentFile=" + setting("environment file path", env_file))
    changed = {k: v for k, v in sorted(spec.env_changes.items()) if v is not None}
    if changed:
        lines.append("Environment=" + " ".join(quote_assignment(k, v) for k, v in changed.items()))
    unset = sorted(k for k, v in spec.env_changes.items() if v is None)
    for name in unset:
        check_variable(name, "")
    if unset:
        lines.append("UnsetEnvironment=" + " ".join(unset))
    lines += restart_lines(spec)
    lines += [
        "KillMode=control-group",
        "KillSignal=SIGINT",
        # 0 would turn the timeout off: a negative ladder (launch kills at once) is 1 µs
        "TimeoutStopSec=" + timespan(spec.sigterm_timeout + spec.sigkill_timeout, least=1e-6),
        "SyslogIdentifier=" + setting("process name", spec.label),
    ]
    return "\n".join(lines) + "\n"


# The launch service's start timeout: readiness (graph discovery, lifecycle bring-up) plus the
# longest timer delay before a process starts.
READY_MARGIN = 90.0
# Its stop: mlaunch's own ladder per process runs in parallel; this is on top of the longest.
STOP_MARGIN = 10.0


def launch_service_text(
    units: list[Unit],
    command: list[str],
    *,
    target: str,
    env_file: str,
    cwd: str,
    user: str | None,
    description: str,
) -> str:
    """The ``Type=notify`` service that runs the whole launch under mlaunch (``command``): it is
    started once mlaunch says READY=1 (mlaunch test's checks), watched by WATCHDOG=1, and
    conflicts with the per-process target (one or the other runs the launch)."""
    delay = max((u.delay for u in units), default=0.0)
    ladder = max((u.spec.sigterm_timeout + u.spec.sigkill_timeout for u in units), default=10.0)
    lines = [
        "[Unit]",
        "Description=" + setting("launch file name", f"{description} under mlaunch"),
        f"Conflicts={target}",
        "After=network-online.target",
        "Wants=network-online.target",
        "",
        "[Service]",
        "Type=notify",
        "NotifyAccess=main",
        f"TimeoutStartSec={timespan(READY_MARGIN + delay)}",
        "WatchdogSec=30",
    ]
    if user:
        lines.append("User=" + user_setting(user))
    lines += [
        "ExecStart=" + " ".join(quote_exec(w) for w in command),
        "WorkingDirectory=" + setting("working directory", cwd),
        "EnvironmentFile=" + setting("environment file path", env_file),
        "Restart=on-failure",
        "RestartSec=2",
        # SIGINT to mlaunch alone: its stop ladder stops the processes, then systemd's SIGKILL
        "KillMode=mixed",
        "KillSignal=SIGINT",
        f"TimeoutStopSec={timespan(ladder + STOP_MARGIN, least=1e-6)}",
        "",
        "[Install]",
        "WantedBy=multi-user.target",
    ]
    return "\n".join(lines) + "\n"


def user_setting(user: str) -> str:
    """``User=``'s value: a user name or a numeric id, as systemd accepts them, else refused."""
    if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_.-]{0,30}\$?|[0-9]{1,10}", user):
        raise UnsafeValue(
            f"--user {user!r} is not a user name systemd accepts (letters, digits, '_', '-', '.',"
            " not starting with a digit or '-', at most 31 characters) nor a numeric id"
        )
    return user


def restart_lines(spec: ProcessSpec) -> list[str]:
    mode = spec.respawn.mode
    if mode == "never":
        return ["Restart=no"]
    restart = "always" if mode == "always" else "on-failure"
    return [f"Restart={restart}", f"RestartSec={timespan(spec.respawn.delay)}"]


def target_text(units: list[Unit], description: str) -> str:
    lines = [
        "[Unit]",
        "Description=" + setting("launch file name", f"{description} (mlaunch export)"),
    ]
    if units:
        lines.append("Wants=" + " ".join(u.name for u in units))
    required = [u.name for u in units if u.spec.required]
    if required:
        lines.append("BindsTo=" + " ".join(required))
    lines += ["", "[Install]", "WantedBy=multi-user.target"]
    return "\n".join(lines) + "\n"


def install_params(units: list[Unit], install_dir: str) -> list[tuple[str, str]]:
    """Point each process's argv at its params files' copies next to the units.

    Returns the copies to make, (source, name under ``params/``), once every unit is known to
    be writable."""
    copies: list[tuple[str, str]] = []
    for unit in units:
        spec = unit.spec
        argv = list(spec.argv)
        count = 0
        for i in range(1, len(argv)):
            if argv[i - 1] != "--params-file" or not os.path.isfile(argv[i]):
                continue
            name = f"{unit.name.removesuffix('.service')}-{count}.yaml"
            copies.append((argv[i], name))
            argv[i] = os.path.join(install_dir, "params", name)
            count += 1
        spec.argv = tuple(argv)
    return copies


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
        "",
        f"Or run the whole launch under mlaunch: `{prefix}.service` (`Type=notify`) is started"
        " once mlaunch says the launch is ready (its processes up, its nodes in the ROS graph,"
        " lifecycle nodes active: the checks of `mlaunch test`), and restarted when a process"
        " it watches dies (no more watchdog pings). It conflicts with the target: one or the"
        " other runs the launch. It needs mlaunch on the robot (the path in its ExecStart=) and"
        f" the launch file's folder, copied to {install_dir}/launch:",
        "",
        f"    sudo systemctl link {shlex.quote(install_dir)}/{prefix}.service"
        f" && sudo systemctl enable --now {prefix}.service",
    ]
    if warnings:
        lines += ["", "## Warnings", ""] + [f"- {w}" for w in warnings]
    return "\n".join(lines) + "\n"
