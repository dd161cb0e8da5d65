"""Substitutions: lazily evaluated pieces of text, with the names and semantics of ROS 2 launch.

A substitution is data until ``perform(context)`` is called while resolving; ``describe()`` shows
it unresolved (``--print`` of deferred actions, ``--show-args`` defaults). The base class and
helpers are mlaunch.launch.substitution's, the boolean substitutions
mlaunch.launch.boolean_substitutions'; every name is served from here too, as ROS 2 does.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable

from mlaunch.launch.boolean_substitutions import (
    AllSubstitution,
    AndSubstitution,
    AnySubstitution,
    EqualsSubstitution,
    IfElseSubstitution,
    NotEqualsSubstitution,
    NotSubstitution,
    OrSubstitution,
    evaluate_condition_expression,
    to_bool,
)
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
from mlaunch.plan.errors import SubstitutionFailure

# typing (~4 ms) and subprocess (~3 ms, with selectors and threading) are not imported at start-up:
# annotations are strings, and only Command() runs a program. mypy treats this name as
# typing.TYPE_CHECKING.
TYPE_CHECKING = False
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext


class LaunchConfiguration(Substitution):
    """The value of a launch configuration (an argument or a ``let``), with an optional default."""

    def __init__(self, variable_name: SomeSubstitutionsType, *, default: Any = None) -> None:
        self.variable_name = normalize(variable_name)
        if default is None:
            self.default: Subs | None = None
        elif isinstance(default, (str, Substitution, Path, list, tuple)):
            self.default = normalize(default)
        else:
            self.default = normalize(str(default))

    def perform(self, context: LaunchContext) -> str:
        name = perform_substitutions(context, self.variable_name)
        configs = context.launch_configurations
        if name in configs:
            value = configs[name]
            return value if isinstance(value, str) else str(value)
        if self.default is not None:
            return perform_substitutions(context, self.default)
        from mlaunch.plan.errors import did_you_mean

        hint = did_you_mean(name, (k for k in configs if isinstance(k, str)))
        raise SubstitutionFailure(f"launch configuration {name!r} does not exist{hint}")

    def describe(self) -> str:
        name = "".join(s.describe().strip("'") for s in self.variable_name)
        return f"LaunchConfig({name!r})"


class EnvironmentVariable(Substitution):
    """An environment variable of the launch (``$(env NAME [default])``)."""

    def __init__(self, name: SomeSubstitutionsType, *, default_value: Any = None) -> None:
        self.name = normalize(name)
        self.default_value = None if default_value is None else normalize(default_value)

    def perform(self, context: LaunchContext) -> str:
        name = perform_substitutions(context, self.name)
        value = context.environment.get(name)
        if value is not None:
            return value
        if self.default_value is not None:
            return perform_substitutions(context, self.default_value)
        raise SubstitutionFailure(
            f"environment variable {name!r} does not exist: it is not set and has no default"
            " (give one: EnvironmentVariable(name, default_value=...) or $(env NAME default))"
        )

    def describe(self) -> str:
        return f"EnvVar({describe(self.name)})"


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
        unique = int.from_bytes(os.urandom(8), "big") >> 1
        raw = f"{name}_{os.uname().nodename}_{os.getpid()}_{unique}"
        value = raw.replace(".", "_").replace("-", "_").replace(":", "_")
        context.launch_configurations[key] = value
        return value

    def describe(self) -> str:
        return f"AnonName({describe(self.name)})"


class ThisLaunchFile(Substitution):
    """The path of the launch file being resolved (``$(filename)``)."""

    def perform(self, context: LaunchContext) -> str:
        path = context.current_launch_file_path
        if path is None:
            raise SubstitutionFailure("ThisLaunchFile used outside of a launch file")
        return _checked(context, "current_launch_file_path", path, "ThisLaunchFile")

    def describe(self) -> str:
        return "ThisLaunchFile()"


class ThisLaunchFileDir(Substitution):
    """The directory of the launch file being resolved (``$(dirname)``)."""

    def perform(self, context: LaunchContext) -> str:
        # The local launch sets with the file (a script may set it itself, as launch's tests do).
        directory = context.locals.get("current_launch_file_directory")
        if directory is not None:
            return _checked(
                context, "current_launch_file_directory", str(directory), "ThisLaunchFileDir"
            )
        path = context.current_launch_file_path
        if path is None:
            raise SubstitutionFailure("ThisLaunchFileDir used outside of a launch file")
        return os.path.dirname(path)

    def describe(self) -> str:
        return "ThisLaunchFileDir()"


def _checked(context: LaunchContext, key: str, value: str, what: str) -> str:
    """``value``, with mlaunch.launch.file_locals's warning when it is an included file's that
    PR #862's rule would not give (only then is that module loaded)."""
    if "mlaunch_own_file_locals" not in getattr(context, "_locals", ()):
        return value
    from mlaunch.launch.file_locals import checked

    return checked(context, key, value, what)


class LaunchLogDir(Substitution):
    """The log directory of this run (``$(log_dir)``)."""

    def perform(self, context: LaunchContext) -> str:
        if context.log_dir:
            return context.log_dir
        # A context no run made: launch.logging's folder, made on first use, as launch's.
        from mlaunch.launch.logging import launch_config

        return launch_config.log_dir

    def describe(self) -> str:
        return "LaunchLogDir()"


class LocalSubstitution(Substitution):
    """An attribute path in the context locals, e.g. ``event.returncode`` inside a handler."""

    def __init__(self, expression: str, description: str | None = None) -> None:
        self.expression = expression
        self.description = description

    def perform(self, context: LaunchContext) -> str:
        # launch evaluates the expression against the locals (``event.cmd[1]``, ``event.text``).
        try:
            value = eval(f"_locals.{self.expression}", {}, {"_locals": context.locals})
        except Exception as e:
            raise SubstitutionFailure(
                f"LocalSubstitution {self.expression!r} failed here: {type(e).__name__}: {e}"
                " (it is only valid where that local is defined, e.g. in an event handler)"
            )
        return str(value)

    def describe(self) -> str:
        return self.description or f"LocalVar({self.expression!r})"


class FileContent(Substitution):
    """The text of a file (``$(file-content path)``)."""

    def __init__(self, path: SomeSubstitutionsType) -> None:
        self.path = normalize(path)

    def perform(self, context: LaunchContext) -> str:
        path = perform_substitutions(context, self.path)
        try:
            with open(path, encoding="utf-8") as f:
                return f.read()
        except FileNotFoundError:
            raise SubstitutionFailure(f"File not found: {path}")
        except OSError as e:
            raise SubstitutionFailure(f"cannot read file {path!r}: {e.strerror}")

    def describe(self) -> str:
        return f"FileContent({describe(self.path)})"


# --- paths and programs ----------------------------------------------------------------------


def which(name: str, path: str) -> str | None:
    """The first executable file ``name`` on ``path`` (shutil.which, without importing shutil)."""
    if os.sep in name:
        return name if os.access(name, os.X_OK) and not os.path.isdir(name) else None
    for folder in path.split(os.pathsep):
        candidate = os.path.join(folder or os.curdir, name)
        if os.access(candidate, os.X_OK) and not os.path.isdir(candidate):
            return candidate
    return None


class PathJoinSubstitution(Substitution):
    """``os.path.join`` of the performed parts; ``/`` extends it."""

    def __init__(self, substitutions: Iterable[SomeSubstitutionsType]) -> None:
        self.substitutions = tuple(normalize(part) for part in substitutions)

    def perform(self, context: LaunchContext) -> str:
        parts = [perform_substitutions(context, part) for part in self.substitutions]
        return os.path.join(*parts) if parts else ""

    def __truediv__(self, other: SomeSubstitutionsType) -> PathJoinSubstitution:
        joined = PathJoinSubstitution([])
        joined.substitutions = (*self.substitutions, normalize(other))
        return joined

    def describe(self) -> str:
        return "PathJoin(" + ", ".join(describe(p) for p in self.substitutions) + ")"


class PathSubstitution(Substitution):
    """A path that ``/`` extends into a PathJoinSubstitution (Jazzy's ``PathSubstitution``)."""

    def __init__(self, path: SomeSubstitutionsType) -> None:
        self.path = normalize(path)

    def perform(self, context: LaunchContext) -> str:
        return perform_substitutions(context, self.path)

    def __truediv__(self, other: SomeSubstitutionsType) -> PathJoinSubstitution:
        return PathJoinSubstitution([self, other])

    def describe(self) -> str:
        return f"Path({describe(self.path)})"


class FindExecutable(Substitution):
    """The full path of a program on PATH (``$(find-exec name)``)."""

    def __init__(self, *, name: SomeSubstitutionsType) -> None:
        self.name = normalize(name)

    def perform(self, context: LaunchContext) -> str:
        name = perform_substitutions(context, self.name)
        found = which(name, context.environment.get("PATH", os.defpath))
        if found is None:
            raise SubstitutionFailure(f"executable {name!r} not found on the PATH")
        return found

    def describe(self) -> str:
        return f"FindExec({describe(self.name)})"


# Programs Command() may run inside mlaunch instead of spawning them (xacro: no interpreter start).
# Each entry takes (argv, context) and returns (returncode, stdout, stderr).
InProcessCommand = Callable[[list[str], "LaunchContext"], tuple[int, str, str]]
IN_PROCESS_COMMANDS: dict[str, InProcessCommand] = {}


class Command(Substitution):
    """The standard output of a command run at resolve time (``$(command 'cmd' [on_stderr])``).

    As in ROS 2, a non-zero exit fails and, by default, so does any output on stderr
    (``on_stderr``: ``fail``, ``warn``, ``ignore`` or ``capture``).
    """

    ON_STDERR = ("fail", "warn", "ignore", "capture")

    def __init__(self, command: SomeSubstitutionsType, *, on_stderr: Any = "fail") -> None:
        self.command = normalize(command)
        self.on_stderr = normalize(on_stderr)

    def perform(self, context: LaunchContext) -> str:
        text = perform_substitutions(context, self.command)
        on_stderr = perform_substitutions(context, self.on_stderr)
        if on_stderr not in self.ON_STDERR:
            raise SubstitutionFailure(
                f"Command on_stderr is {on_stderr!r}; valid: {', '.join(self.ON_STDERR)}"
            )
        import shlex

        try:
            argv = shlex.split(text)
        except ValueError as e:
            raise SubstitutionFailure(f"cannot split command {text!r}: {e}")
        if not argv:
            raise SubstitutionFailure("Command is empty")
        rc, out, err = run_command(argv, context)
        if rc != 0:
            detail = err.strip().splitlines()[-1] if err.strip() else f"exit status {rc}"
            # launch's words first, then what mlaunch adds (the status, stderr's last line)
            raise SubstitutionFailure(
                f"executed command failed. Command: {text} (exit status {rc}: {detail})"
            )
        if err:
            if on_stderr == "fail":
                raise SubstitutionFailure(
                    f"executed command showed stderr output. Command: {text}\n"
                    f"Captured stderr output: {err.strip()[:500]}\n"
                    "(the command wrote to stderr: pass on_stderr='warn' or 'ignore' to accept"
                    " that)"
                )
            if on_stderr == "warn":
                context.warn(f"command {text!r} wrote to stderr: {err.strip()}")
            elif on_stderr == "capture":
                out += err
        return out

    def describe(self) -> str:
        return f"Command({describe(self.command)})"


def run_command(argv: list[str], context: LaunchContext) -> tuple[int, str, str]:
    """Run a command for Command(): in-process when a handler is registered, else spawned."""
    handler = IN_PROCESS_COMMANDS.get(os.path.basename(argv[0]))
    if handler is not None:
        return handler(argv, context)
    import subprocess

    try:
        done = subprocess.run(
            argv,
            capture_output=True,
            env=dict(context.environment),
            stdin=subprocess.DEVNULL,
            check=False,
        )
    except FileNotFoundError:
        raise SubstitutionFailure(f"file not found: command {argv[0]!r} not found on the PATH")
    except OSError as e:
        raise SubstitutionFailure(f"cannot run command {argv[0]!r}: {e.strerror}")
    return (
        done.returncode,
        done.stdout.decode("utf-8", "replace"),
        done.stderr.decode("utf-8", "replace"),
    )


class PythonExpression(Substitution):
    """The str() of a Python expression (``$(eval 'expr' [modules])``); math names are bare."""

    def __init__(self, expression: SomeSubstitutionsType, python_modules: Any = ("math",)) -> None:
        self.expression = normalize(expression)
        self.python_modules = python_modules

    def _modules(self, context: LaunchContext) -> list[str]:
        mods = self.python_modules
        if isinstance(mods, (str, Substitution)):
            text = perform(context, mods)
            return [m.strip() for m in text.split(",") if m.strip()]
        return [perform(context, m) for m in mods]

    def perform(self, context: LaunchContext) -> str:
        import importlib
        import math

        expression = perform_substitutions(context, self.expression)
        namespace: dict[str, Any] = {}
        for name in self._modules(context):
            try:
                module = importlib.import_module(name)
            except ImportError as e:
                raise SubstitutionFailure(f"PythonExpression cannot import {name!r}: {e}")
            namespace[name] = module
            if module is math:
                namespace.update({k: v for k, v in vars(math).items() if not k.startswith("_")})
        try:
            return str(eval(expression, {}, namespace))
        except Exception as e:
            message = f"Python expression {expression!r} failed: {type(e).__name__}: {e}"
            raise _failure_of(e, message) from e

    def describe(self) -> str:
        mods = self.python_modules
        listed = [mods] if isinstance(mods, (str, Substitution)) else list(mods)
        modules = ", ".join(describe(normalize(m)) for m in listed)
        return f"PythonExpr({describe(self.expression)}, [{modules}])"


def _failure_of(error: Exception, message: str) -> SubstitutionFailure:
    """A SubstitutionFailure that is also an instance of ``error``'s type: mlaunch reports it
    as one located line, and code written against launch still catches the NameError (or
    whatever the expression raised) that launch lets through."""
    try:
        both = type(type(error).__name__, (SubstitutionFailure, type(error)), {})
        failure: SubstitutionFailure = both(message)
    except TypeError:  # a type that cannot be combined (or built from one message)
        failure = SubstitutionFailure(message)
    return failure


# Newer than Jazzy (launch 3.8, Kilted); --check says so where a file uses them.
from mlaunch.launch.substitutions.for_loop_var import ForEachVar, ForLoopIndex  # noqa: E402
from mlaunch.launch.substitutions.string_join_substitution import (  # noqa: E402
    StringJoinSubstitution,
)

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
