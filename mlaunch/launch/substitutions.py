"""Substitutions: lazily evaluated pieces of text, with the names and semantics of ROS 2 launch.

A substitution is data until ``perform(context)`` is called while resolving; ``describe()`` shows
it unresolved (``--print`` of deferred actions, ``--show-args`` defaults).
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable

from mlaunch.errors import InvalidConditionExpressionError, SubstitutionFailure

# pathlib is not imported: it costs milliseconds at start-up, and os.PathLike covers Path.
Path = os.PathLike

# typing (~4 ms) and subprocess (~3 ms, with selectors and threading) are not imported at start-up:
# annotations are strings, and only Command() runs a program. mypy treats this name as
# typing.TYPE_CHECKING.
TYPE_CHECKING = False
if TYPE_CHECKING:
    from collections.abc import Sequence
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext


class Substitution:
    """Base class: something that becomes a string when the launch is resolved."""

    def perform(self, context: LaunchContext) -> str:
        raise NotImplementedError

    def describe(self) -> str:
        return type(self).__name__ + "(...)"

    def __repr__(self) -> str:
        return self.describe()


# What ROS 2's launch files annotate arguments with; a union of classes, no typing needed.
SomeSubstitutionsType = str | Path | Substitution | Iterable[str | Path | Substitution]
SomeSubstitutionsType_types_tuple = (str, Path, Substitution)
Subs = tuple[Substitution, ...]


def normalize(value: Any) -> Subs:
    """Turn a str, Path, Substitution or iterable of those into a tuple of substitutions.

    Lists concatenate when performed, as in ROS 2 (``['a', LaunchConfiguration('b')]`` is one
    string).
    """
    if isinstance(value, Substitution):
        return (value,)
    if isinstance(value, str):
        return (TextSubstitution(text=value),)
    if isinstance(value, os.PathLike):
        return (TextSubstitution(text=os.fspath(value)),)
    if isinstance(value, (int, float, bool)):
        return (TextSubstitution(text=str(value)),)
    if isinstance(value, Iterable):
        out: list[Substitution] = []
        for item in value:
            out.extend(normalize(item))
        return tuple(out)
    raise TypeError(
        f"expected a str, a Substitution or a list of them, got {type(value).__name__}: {value!r}"
    )


def is_substitution_like(value: Any) -> bool:
    if isinstance(value, (str, Path, Substitution)):
        return True
    return isinstance(value, (list, tuple)) and all(
        isinstance(v, (str, Path, Substitution)) for v in value
    )


def perform_substitutions(context: LaunchContext, subs: Sequence[Substitution]) -> str:
    """Perform each substitution and concatenate the results."""
    if len(subs) == 1:
        return subs[0].perform(context)
    return "".join(s.perform(context) for s in subs)


def perform(context: LaunchContext, value: Any) -> str:
    """Perform any SomeSubstitutionsType value (str, Substitution, list) to a string."""
    if isinstance(value, str):
        return value
    return perform_substitutions(context, normalize(value))


def describe(value: Any) -> str:
    """Describe an unresolved value: text in quotes, substitutions by their describe()."""
    subs = normalize(value)
    return " + ".join(s.describe() for s in subs) if subs else "''"


# --- text and configuration -----------------------------------------------------------------


class TextSubstitution(Substitution):
    """Literal text."""

    def __init__(self, *, text: str) -> None:
        self.text = str(text)

    def perform(self, context: LaunchContext) -> str:
        return self.text

    def describe(self) -> str:
        return repr(self.text)


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
        raise SubstitutionFailure(f"launch configuration {name!r} does not exist")

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
            f"environment variable {name!r} is not set and has no default"
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
        return path

    def describe(self) -> str:
        return "ThisLaunchFile()"


class ThisLaunchFileDir(Substitution):
    """The directory of the launch file being resolved (``$(dirname)``)."""

    def perform(self, context: LaunchContext) -> str:
        path = context.current_launch_file_path
        if path is None:
            raise SubstitutionFailure("ThisLaunchFileDir used outside of a launch file")
        return os.path.dirname(path)

    def describe(self) -> str:
        return "ThisLaunchFileDir()"


class LaunchLogDir(Substitution):
    """The log directory of this run (``$(log_dir)``)."""

    def perform(self, context: LaunchContext) -> str:
        return context.log_dir

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
            raise SubstitutionFailure(
                f"command {text!r} failed with exit status {rc}: {detail}"
                if err.strip()
                else f"command {text!r} failed with exit status {rc}"
            )
        if err:
            if on_stderr == "fail":
                raise SubstitutionFailure(
                    f"command {text!r} wrote to stderr: {err.strip()[:500]!r}"
                    " (pass on_stderr='warn' or 'ignore' to accept that)"
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
        raise SubstitutionFailure(f"command {argv[0]!r} not found on the PATH")
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
            raise SubstitutionFailure(
                f"Python expression {expression!r} failed: {type(e).__name__}: {e}"
            )

    def describe(self) -> str:
        return f"PythonExpr({describe(self.expression)})"


# --- booleans --------------------------------------------------------------------------------

_TRUE_WORDS = frozenset({"true", "yes", "on", "1", "y"})
_FALSE_WORDS = frozenset({"false", "no", "off", "0", "n"})


def to_bool(text: str, what: str) -> bool:
    """YAML-style boolean, as the boolean substitutions accept (true/yes/on/1 ...)."""
    lowered = text.strip().lower()
    if lowered in _TRUE_WORDS:
        return True
    if lowered in _FALSE_WORDS:
        return False
    raise SubstitutionFailure(f"{what} got {text!r}, which is not a boolean (true/false/1/0)")


def evaluate_condition_expression(text: str) -> bool:
    """The strict rule of IfCondition/UnlessCondition: only true, false, 1 and 0."""
    lowered = text.strip().lower()
    if lowered in ("true", "1"):
        return True
    if lowered in ("false", "0"):
        return False
    raise InvalidConditionExpressionError(
        f"condition expression is {text!r}; valid values are true, false, 1, 0"
    )


def _bool_text(value: bool) -> str:
    return "true" if value else "false"


class NotSubstitution(Substitution):
    def __init__(self, value: SomeSubstitutionsType) -> None:
        self.value = normalize(value)

    def perform(self, context: LaunchContext) -> str:
        return _bool_text(not to_bool(perform_substitutions(context, self.value), "not"))

    def describe(self) -> str:
        return f"Not({describe(self.value)})"


class _Many(Substitution):
    name = ""

    def __init__(self, *args: SomeSubstitutionsType) -> None:
        self.args = tuple(normalize(a) for a in args)

    def _values(self, context: LaunchContext) -> list[bool]:
        return [to_bool(perform_substitutions(context, a), self.name) for a in self.args]

    def describe(self) -> str:
        return f"{type(self).__name__}(" + ", ".join(describe(a) for a in self.args) + ")"


class AndSubstitution(_Many):
    name = "and"

    def __init__(self, left: SomeSubstitutionsType, right: SomeSubstitutionsType) -> None:
        super().__init__(left, right)

    def perform(self, context: LaunchContext) -> str:
        return _bool_text(all(self._values(context)))


class OrSubstitution(_Many):
    name = "or"

    def __init__(self, left: SomeSubstitutionsType, right: SomeSubstitutionsType) -> None:
        super().__init__(left, right)

    def perform(self, context: LaunchContext) -> str:
        return _bool_text(any(self._values(context)))


class AnySubstitution(_Many):
    name = "any"

    def perform(self, context: LaunchContext) -> str:
        return _bool_text(any(self._values(context)))


class AllSubstitution(_Many):
    name = "all"

    def perform(self, context: LaunchContext) -> str:
        return _bool_text(all(self._values(context)))


def _equal(left: str, right: str) -> bool:
    """Bool-aware, then float-aware, else textual comparison (EqualsSubstitution's rule)."""
    bools = {"true": True, "false": False}
    lb, rb = bools.get(left.strip().lower()), bools.get(right.strip().lower())
    if lb is not None or rb is not None:
        if lb is None and left.strip() in ("0", "1"):
            lb = left.strip() == "1"
        if rb is None and right.strip() in ("0", "1"):
            rb = right.strip() == "1"
        if lb is not None and rb is not None:
            return lb == rb
    import math

    try:
        return math.isclose(float(left), float(right))
    except ValueError:
        return left == right


def _equals_operand(value: Any) -> Subs:
    if value is None:
        return (TextSubstitution(text=""),)
    if isinstance(value, bool):
        return (TextSubstitution(text=_bool_text(value)),)
    return normalize(value)


class EqualsSubstitution(Substitution):
    def __init__(self, left: Any, right: Any) -> None:
        self.left = _equals_operand(left)
        self.right = _equals_operand(right)

    def perform(self, context: LaunchContext) -> str:
        left = perform_substitutions(context, self.left)
        right = perform_substitutions(context, self.right)
        return _bool_text(_equal(left, right))

    def describe(self) -> str:
        return f"Equals({describe(self.left)}, {describe(self.right)})"


class NotEqualsSubstitution(EqualsSubstitution):
    def perform(self, context: LaunchContext) -> str:
        return _bool_text(not to_bool(super().perform(context), "not-equals"))

    def describe(self) -> str:
        return f"NotEquals({describe(self.left)}, {describe(self.right)})"


class IfElseSubstitution(Substitution):
    """``if_value`` when the condition holds, else ``else_value``."""

    def __init__(
        self, condition: SomeSubstitutionsType, if_value: Any = None, else_value: Any = None
    ) -> None:
        if if_value is None and else_value is None:
            raise TypeError("IfElseSubstitution needs at least one of if_value and else_value")
        self.condition = normalize(condition)
        self.if_value = normalize("" if if_value is None else if_value)
        self.else_value = normalize("" if else_value is None else else_value)

    def perform(self, context: LaunchContext) -> str:
        chosen = evaluate_condition_expression(perform_substitutions(context, self.condition))
        return perform_substitutions(context, self.if_value if chosen else self.else_value)

    def describe(self) -> str:
        return (
            f"IfElse({describe(self.condition)}, {describe(self.if_value)},"
            f" {describe(self.else_value)})"
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
    "IfElseSubstitution",
    "LaunchConfiguration",
    "LaunchLogDir",
    "LocalSubstitution",
    "NotEqualsSubstitution",
    "NotSubstitution",
    "OrSubstitution",
    "PathJoinSubstitution",
    "PathSubstitution",
    "PythonExpression",
    "SomeSubstitutionsType",
    "Substitution",
    "SubstitutionFailure",
    "TextSubstitution",
    "ThisLaunchFile",
    "ThisLaunchFileDir",
]
