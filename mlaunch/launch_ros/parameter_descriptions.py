"""``launch_ros.parameter_descriptions`` (also ``launch_ros.descriptions``): typed parameter values.

- ``ParameterValue(value, *, value_type=None)``: a value whose type is forced when performed;
  ``value_type=str`` keeps a substitution's text as text (a URDF from xacro stays a string,
  never YAML-parsed). Without a type, substitution results are read with YAML rules.
- ``Parameter(name, value, *, value_type=None)``: a single ``-p name:=value`` on the command line.
- ``ParameterFile(param_file, *, allow_substs=False)``: a params file; with ``allow_substs`` its
  ``$(...)`` are performed and the result is written to a new file.
- ``ComposableNode``: the description of a component (in
  mlaunch.launch_ros.descriptions.composable_node).

The typing rules are launch's ``type_utils``: plain values are checked against ``value_type``
when built; substitutions are performed and coerced when the node is resolved (``int``/``float``
with Python's conversion, ``bool`` and lists with YAML, ``str`` as is).
"""

from __future__ import annotations

import os
import sys
from collections.abc import Iterable

from mlaunch.launch.substitution import Substitution, describe, normalize, perform_substitutions
from mlaunch.plan.errors import (
    LaunchFileError,
    LaunchFileTypeError,
    SubstitutionFailure,
    SubstitutionValueError,
)

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from pathlib import Path
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext

SCALAR_TYPES = (int, float, bool, str)


def is_path(value: object) -> bool:
    """``isinstance(value, pathlib.Path)`` without importing pathlib (with re, fnmatch,
    urllib.parse and ipaddress: ~3 ms before a Node launch's first child): there is no Path
    before pathlib is imported."""
    pathlib = sys.modules.get("pathlib")
    return pathlib is not None and isinstance(value, pathlib.Path)


Subs = tuple[Substitution, ...]


# --- value types --------------------------------------------------------------------------------


def extract_type(value_type: Any) -> tuple[type | None, bool]:
    """``int`` -> (int, False); ``List[int]`` or ``list[int]`` -> (int, True); None: YAML rules."""
    if value_type is None:
        return None, False
    # ``list[int]`` and ``typing.List[int]`` both carry these (typing itself costs ~4 ms).
    if getattr(value_type, "__origin__", None) is list:
        args: tuple[Any, ...] = getattr(value_type, "__args__", ())
        if len(args) == 1 and args[0] in SCALAR_TYPES:
            return args[0], True
    elif value_type in SCALAR_TYPES:
        return value_type, False
    raise LaunchFileError(
        f"value_type {value_type!r} is not a parameter type; valid: int, float, bool, str,"
        " List[int], List[float], List[bool], List[str] (or None for YAML rules)"
    )


def type_name(value_type: Any) -> str:
    scalar, is_list = extract_type(value_type)
    if scalar is None:
        return "None"
    return f"List[{scalar.__name__}]" if is_list else scalar.__name__


def is_substitution(value: Any) -> bool:
    """A Substitution, or a non-empty list of text and substitutions (one substitution at least)."""
    if isinstance(value, Substitution):
        return True
    if isinstance(value, (list, tuple)) and value:
        return all(isinstance(v, (str, Substitution)) for v in value) and any(
            isinstance(v, Substitution) for v in value
        )
    return False


def _is_instance(value: Any, scalar: type | None, is_list: bool) -> bool:
    if scalar is None:
        return _valid_plain(value)
    if is_list:
        return isinstance(value, list) and all(isinstance(v, scalar) for v in value)
    return isinstance(value, scalar)


def _valid_plain(value: Any) -> bool:
    """A scalar, or a list of one scalar type (text may mix in, as launch allows)."""
    if isinstance(value, list):
        kinds = {type(v) for v in value}
        kinds.discard(str)
        return len(kinds) <= 1 and kinds <= set(SCALAR_TYPES)
    return isinstance(value, SCALAR_TYPES)


def _valid_loaded(value: Any) -> bool:
    """A YAML result a parameter may hold: a scalar, or a list of one type (text too, but not
    mixed with other types, unlike a plain list; launch's check with ``can_be_str=False``)."""
    if isinstance(value, list):
        first = next((type(v) for v in value if type(v) is not str), str)
        return first in SCALAR_TYPES and all(isinstance(v, first) for v in value)
    return isinstance(value, SCALAR_TYPES)


def normalize_typed(value: Any, value_type: Any) -> Any:
    """A plain value checked against ``value_type``, or substitutions kept for later.

    Returns a scalar, a ``Subs`` tuple (performed later), or a list whose items are scalars or
    ``Subs`` tuples.
    """
    scalar, is_list = extract_type(value_type)
    if is_path(value):
        value = str(value)
    if isinstance(value, SCALAR_TYPES):
        if not _is_instance(value, scalar, is_list):
            raise LaunchFileTypeError(f"value {value!r} is not of type {type_name(value_type)}")
        return value
    if is_substitution(value):
        return normalize(value)
    if not isinstance(value, Iterable) or isinstance(value, (bytes, dict)):
        raise LaunchFileTypeError(
            f"a parameter value must be a scalar, a substitution or a list of them, got"
            f" {type(value).__name__}: {value!r}"
        )
    items = list(value)
    if value_type is not None and not is_list:
        raise LaunchFileTypeError(
            f"value {items!r} is a list, but value_type {type_name(value_type)} is not"
        )
    kinds: set[type] = set()
    out: list[Any] = []
    for item in items:
        if isinstance(item, SCALAR_TYPES):
            kinds.add(type(item))
            out.append(item)
        elif is_substitution(item):
            kinds.add(Substitution)
            out.append(normalize(item))
        else:
            raise LaunchFileTypeError(
                f"list parameter item {item!r} is not a scalar or a substitution (in {items!r})"
            )
    _check_list_kinds(kinds, scalar, items)
    if kinds <= {int, float, Substitution} and (float in kinds or scalar is float):
        out = [float(v) if isinstance(v, int) else v for v in out]
    return out


def _check_list_kinds(kinds: set[type], scalar: type | None, items: list[Any]) -> None:
    """A list is uniform: text, bools, ints, or numbers (floats); substitutions fit any."""
    plain = kinds - {Substitution}
    for allowed, fits in (({str}, str), ({bool}, bool), ({int}, int), ({int, float}, float)):
        if plain <= allowed:
            # ints also fit a List[float] (launch_ros refuses that; nothing depends on it)
            if scalar is None or not plain or scalar is fits or (scalar is float and fits is int):
                return
            break
    names = ", ".join(sorted(k.__name__ for k in plain))
    want = f"List[{scalar.__name__}]" if scalar else "one type"
    raise LaunchFileTypeError(f"list parameter {items!r} holds {names}; expected {want}")


def perform_typed(context: LaunchContext, value: Any, value_type: Any) -> Any:
    """Perform a value from ``normalize_typed`` and coerce it to ``value_type``."""
    scalar, is_list = extract_type(value_type)
    if isinstance(value, tuple):
        return coerce(perform_substitutions(context, value), value_type)
    if isinstance(value, list):
        item_type = scalar if is_list else None
        return [
            coerce(perform_substitutions(context, v), item_type) if isinstance(v, tuple) else v
            for v in value
        ]
    return value


def coerce(text: str, value_type: Any) -> Any:
    """Performed text -> a value of ``value_type`` (launch's coerce_to_type)."""
    scalar, is_list = extract_type(value_type)
    if scalar is None:
        if not text:
            return text  # launch forwards empty text as is: YAML would read it as null
        loaded = _yaml(text, "a parameter value")
        if not _valid_loaded(loaded):
            raise SubstitutionValueError(
                f"value {text!r} read as YAML gives {type(loaded).__name__}, not a parameter"
                " type (a scalar or a uniform list); to keep it as text use"
                " ParameterValue(value, value_type=str)"
            )
        return loaded
    if is_list:
        loaded = _yaml(text, f"a List[{scalar.__name__}]")
        if isinstance(loaded, list) and scalar is float:
            # ints are floats here too (launch_ros refuses '[1, 2]' as List[float])
            loaded = [float(v) if type(v) is int else v for v in loaded]
        if not isinstance(loaded, list) or not all(_is_scalar(v, scalar) for v in loaded):
            raise SubstitutionValueError(f"value {text!r} is not a List[{scalar.__name__}]")
        return loaded
    if scalar is str:
        return text
    if scalar in (int, float):
        try:
            return scalar(text)
        except ValueError:
            raise SubstitutionValueError(f"value {text!r} is not {scalar.__name__}")
    loaded = _yaml(text, "a bool")
    if not isinstance(loaded, bool):
        raise SubstitutionValueError(f"value {text!r} is not a bool (true/false)")
    return loaded


def _is_scalar(value: Any, scalar: type) -> bool:
    return isinstance(value, scalar) and not (scalar is int and isinstance(value, bool))


def _yaml(text: str, what: str) -> Any:
    import yaml

    from mlaunch.plan.yamldata import load as load_yaml

    try:
        return load_yaml(text, what)
    except yaml.YAMLError as e:
        problem = str(e).splitlines()[0] if str(e) else type(e).__name__
        raise SubstitutionValueError(f"value {text[:200]!r} cannot be read as {what}: {problem}")


def as_given(value: Any) -> Any:
    """A value from ``normalize_typed`` in launch's shapes: substitutions as lists."""
    if isinstance(value, tuple):
        return list(value)
    if isinstance(value, list):
        return [list(v) if isinstance(v, tuple) else v for v in value]
    return value


def describe_value(value: Any) -> str:
    if isinstance(value, tuple):
        return describe(value)
    if isinstance(value, list):
        return "[" + ", ".join(describe_value(v) for v in value) + "]"
    return repr(value)


# --- descriptions -------------------------------------------------------------------------------


class ParameterValue:
    """A parameter value with an optional forced type (``value_type``)."""

    def __init__(self, value: Any, *, value_type: Any = None) -> None:
        self._value = normalize_typed(value, value_type)
        self.value_type = value_type
        self._evaluated: Any = None

    @property
    def value(self) -> Any:
        """The value once evaluated; before, as given (substitutions as lists, as in launch)."""
        return self._evaluated if self._evaluated is not None else as_given(self._value)

    def evaluate(self, context: LaunchContext) -> Any:
        self._evaluated = perform_typed(context, self._value, self.value_type)
        return self._evaluated

    def __str__(self) -> str:
        return (
            f"launch_ros.description.ParameterValue(value={describe_value(self._value)},"
            f" value_type={type_name(self.value_type)})"
        )

    __repr__ = __str__


class Parameter:
    """One parameter given on the command line as ``-p name:=value``."""

    def __init__(self, name: Any, value: Any, *, value_type: Any = None) -> None:
        if not (isinstance(name, (str, Substitution, list, tuple)) or is_path(name)):
            raise LaunchFileError(f"parameter name must be text or substitutions, got {name!r}")
        self._name = normalize(name)
        self._value = ParameterValue(value, value_type=value_type)
        self._evaluated_name: str | None = None

    @property
    def name(self) -> Any:
        return self._evaluated_name if self._evaluated_name is not None else list(self._name)

    @property
    def value(self) -> Any:
        return self._value.value

    @property
    def value_type(self) -> Any:
        return self._value.value_type

    def evaluate(self, context: LaunchContext) -> tuple[str, Any]:
        name = perform_substitutions(context, self._name)
        value = self._value.evaluate(context)
        self._evaluated_name = name
        return name, value

    def __str__(self) -> str:
        return (
            f"launch_ros.description.Parameter(name={describe(self._name)},"
            f" value={describe_value(self._value._value)},"
            f" value_type={type_name(self.value_type)})"
        )

    __repr__ = __str__


class ParameterFile:
    """A params file; with ``allow_substs`` its ``$(...)`` are performed into a new file."""

    def __init__(self, param_file: Any, *, allow_substs: Any = False) -> None:
        if isinstance(param_file, bytes):
            param_file = os.fsdecode(param_file)
        elif isinstance(param_file, os.PathLike):
            param_file = os.fspath(param_file)
        self._param_file = normalize(param_file)
        if isinstance(allow_substs, bool):
            self._allow_substs: Any = allow_substs
        else:
            self._allow_substs = normalize_typed(allow_substs, bool)
        self._evaluated: Path | None = None
        self.created = False  # evaluate() wrote a substituted copy

    @property
    def param_file(self) -> Any:
        return self._evaluated if self._evaluated is not None else list(self._param_file)

    @property
    def allow_substs(self) -> Any:
        return self._allow_substs

    def evaluate(self, context: LaunchContext, temp_dir: str | None = None) -> Path:
        """The file to pass: the file itself, or its substituted copy in ``temp_dir``."""
        from pathlib import Path

        path = Path(perform_substitutions(context, self._param_file))
        self.created = bool(perform_typed(context, self._allow_substs, bool))
        if self.created:
            path = Path(substituted_copy(context, path, temp_dir))
        self._evaluated = path
        return path

    def cleanup(self) -> None:
        """Remove the substituted copy ``evaluate`` wrote, if any; ``param_file`` is then the
        file as given again. A file of a run is removed with its node's process instead."""
        if self.created and self._evaluated is not None:
            try:
                os.unlink(self._evaluated)
            except FileNotFoundError:
                pass
            self._evaluated = None
            self.created = False

    def __str__(self) -> str:
        return (
            f"launch_ros.description.ParameterFile(param_file={describe(self._param_file)},"
            f" allow_substs={describe_value(self._allow_substs)})"
        )

    __repr__ = __str__


def substituted_copy(context: LaunchContext, path: Path, temp_dir: str | None) -> str:
    """Perform the ``$(...)`` in a params file and write the result to a new file."""
    from mlaunch.launch.frontend.template import TemplateError
    from mlaunch.launch_ros.subst import parse_template

    try:
        text = path.read_text(encoding="utf-8")
    except OSError as e:
        raise SubstitutionFailure(
            f"parameter file {str(path)!r} cannot be read (allow_substs): {e.strerror}"
        )
    try:
        parts = parse_template(text)
    except TemplateError as e:
        line = text.count("\n", 0, e.index) + 1
        raise SubstitutionFailure(f"{path}:{line}: {e.message}")
    performed = perform_substitutions(context, normalize(parts))
    import yaml

    from mlaunch.plan.yamldata import load as load_yaml

    try:
        load_yaml(performed, str(path))
    except yaml.YAMLError as e:
        raise SubstitutionFailure(
            f"parameter file {str(path)!r} is not valid YAML once substituted: {e}"
        )
    from mlaunch.ros.files import write_temp

    return write_temp("launch_params_", performed, temp_dir)


__all__ = [
    "Parameter",
    "ParameterFile",
    "ParameterValue",
]
