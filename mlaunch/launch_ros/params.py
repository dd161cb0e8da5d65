"""Node parameters evaluated exactly as launch_ros does, and the params files written for them.

``Node(parameters=[...])`` takes, in order, dicts (each becomes one temporary params file),
params-file paths or ``ParameterFile`` (passed with ``--params-file``) and ``Parameter``
descriptions (passed with ``-p name:=value``). The typing rules of a dict value:

- ``bool``, ``int``, ``float``, ``bytes`` and plain ``str`` keep their Python type;
- a substitution (or a list of text and substitutions, which concatenates) is performed and the
  text read with YAML (``'true'`` -> bool, ``'1.0'`` -> float, ``''`` -> empty string);
  anything YAML reads as a map or null is an error that suggests ``ParameterValue(...,
  value_type=str)``;
- a list must be uniform: all ints, all bools, all text, or ints and floats (-> floats); a list
  mixing text with substitutions is one concatenated string unless each item is its own list;
- ``ParameterValue`` forces its type;
- nested dicts are flattened to dotted names (``{'a': {'b': 1}}`` -> ``a.b: 1``).

A file is ``{<key>: {ros__parameters: {...}}}`` dumped by ``yaml.dump(default_flow_style=
False)`` (sorted keys), where the key is the node's full name when both its name and namespace
are known, else ``/**``. Deliberate difference: lists are written as YAML lists, where launch_ros
writes Python tuples (``!!python/tuple``, which only rcl's lenient parser accepts).
"""

from __future__ import annotations

import os
import re
from collections.abc import Mapping, Sequence

from mlaunch.launch.substitution import (
    Substitution,
    TextSubstitution,
    describe,
    normalize,
    perform_substitutions,
)
from mlaunch.launch.substitutions.launch_configuration import LaunchConfiguration
from mlaunch.launch_ros.parameter_descriptions import (
    Parameter,
    ParameterFile,
    ParameterValue,
    is_path,
    is_substitution,
)
from mlaunch.plan.errors import LaunchFileTypeError, SubstitutionFailure, SubstitutionTypeError
from mlaunch.plan.value import Value
from mlaunch.ros.files import write_temp

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable
    from typing import Any, TypeAlias

    from mlaunch.launch.launch_context import LaunchContext

Subs = tuple[Substitution, ...]
PARAMS_FILE_PREFIX = "launch_params_"
_HINT = (
    "; if the parameter is meant to be a string, wrap it in"
    " launch_ros.parameter_descriptions.ParameterValue(value, value_type=str)"
)


# --- normalized values (built with the Node, performed when it is resolved) ---------------------


class Plain(Value):
    """A value that is already typed (bool, int, float, bytes, str, or a uniform tuple)."""

    _fields = ("value",)
    __slots__ = _fields

    def __init__(self, value: Any) -> None:
        self.value = value


class Text(Value):
    """Substitutions performed to one string, then read with YAML."""

    _fields = ("subs",)
    __slots__ = _fields

    def __init__(self, subs: Subs) -> None:
        self.subs = subs


class Items(Value):
    """A list whose items are typed values or substitutions, each read with YAML."""

    _fields = ("items",)
    __slots__ = _fields

    def __init__(self, items: tuple[Any, ...]) -> None:
        self.items = items  # scalars, or Subs tuples


if TYPE_CHECKING:
    NormalizedValue: TypeAlias = Plain | Text | Items | ParameterValue
    NormalizedDict: TypeAlias = dict[Subs, NormalizedValue]
    NormalizedEntry: TypeAlias = NormalizedDict | ParameterFile | Parameter


def normalize_parameters(
    parameters: Any, dict_normalizer: Callable[[Mapping[Any, Any]], Any] | None = None
) -> tuple[NormalizedEntry, ...]:
    """``Node(parameters=...)`` checked and normalized when the Node is built; dicts by
    ``dict_normalizer`` if given (launch_ros.utilities gives launch_ros's shapes)."""
    if isinstance(parameters, (str, Mapping)) or not isinstance(parameters, Sequence):
        raise LaunchFileTypeError(
            f"parameters must be a list of dicts, params-file paths and Parameter entries,"
            f" got {type(parameters).__name__}: {parameters!r:.120}"
        )
    out: list[NormalizedEntry] = []
    for entry in parameters:
        if isinstance(entry, Mapping):
            out.append((dict_normalizer or normalize_dict)(entry))
        elif isinstance(entry, (Parameter, ParameterFile)):
            out.append(entry)
        elif isinstance(entry, (str, Substitution)) or is_path(entry) or is_substitution(entry):
            out.append(ParameterFile(entry))
        else:
            raise LaunchFileTypeError(
                f"a parameters entry must be a dict, a params-file path or a Parameter, got"
                f" {type(entry).__name__}: {entry!r:.120}"
            )
    return tuple(out)


def normalize_dict(params: Mapping[Any, Any], prefix: Subs | None = None) -> NormalizedDict:
    """Names become substitution tuples (nested dicts joined with '.'), values normalized."""
    out: NormalizedDict = {}
    for raw_name, value in params.items():
        name = parameter_name(raw_name)
        if prefix:
            name = (*prefix, TextSubstitution(text="."), *name)
        if isinstance(value, Mapping):
            out.update(normalize_dict(value, name))
        else:
            out[name] = normalize_value(value, name)
    return out


def parameter_name(name: Any) -> Subs:
    """A parameter name as substitutions: text, a substitution, or a sequence of them."""
    if isinstance(name, (str, Substitution)) or (
        isinstance(name, (list, tuple)) and all(isinstance(n, (str, Substitution)) for n in name)
    ):
        return normalize(name)
    raise LaunchFileTypeError(
        f"a parameter name must be text, a substitution or a list of them, got"
        f" {type(name).__name__}: {name!r:.80}"
    )


def normalize_value(value: Any, name: Subs = ()) -> NormalizedValue:
    if isinstance(value, ParameterValue):
        return value
    if isinstance(value, (bool, int, float, bytes, str)):
        return Plain(value)
    if is_path(value):
        return Plain(str(value))
    if isinstance(value, Substitution):
        return Text((value,))
    if isinstance(value, Sequence):
        return _normalize_list(value, name)
    raise LaunchFileTypeError(
        f"parameter {describe(name)}: a value must be a scalar, a substitution, a list or a dict,"
        f" got {type(value).__name__}: {value!r:.120}"
    )


def _normalize_list(value: Sequence[Any], name: Subs) -> NormalizedValue:
    kinds = {_kind(item, name) for item in value}
    if kinds == {int}:
        return Plain(tuple(int(v) for v in value))
    if kinds in ({float}, {int, float}):
        return Plain(tuple(float(v) for v in value))
    if Substitution in kinds and kinds <= {str, Substitution}:
        return Text(normalize(value))  # text and substitutions concatenate into one string
    if kinds == {bool}:
        return Plain(tuple(bool(v) for v in value))
    # Each item on its own (text, numbers, lists of substitutions): read each with YAML later.
    return Items(
        tuple(v if isinstance(v, (str, bool, int, float)) else normalize(v) for v in value)
    )


def _kind(item: Any, name: Subs) -> type:
    if isinstance(item, Substitution):
        return Substitution
    if isinstance(item, (str, bool, int, float)):
        return type(item)
    if isinstance(item, (list, tuple)) and all(isinstance(i, (str, Substitution)) for i in item):
        return tuple
    raise LaunchFileTypeError(
        f"parameter {describe(name)}: list item {item!r:.80} is not a scalar, a substitution or a"
        " list of substitutions"
    )


# --- evaluation -----------------------------------------------------------------------------


def evaluate_dict(
    context: LaunchContext, params: NormalizedDict, *, check_clock: bool = True
) -> dict[str, Any]:
    """Names performed, values typed: the dict written to a params file.

    ``check_clock=False`` passes a use_sim_time that is not a boolean on, as ROS 2 does: for the
    contents of a params file, which reach a Node unread and a component in its LoadNode request
    (the container refuses that one load, with its message)."""
    out: dict[str, Any] = {}
    for raw_name, value in params.items():
        name = perform_substitutions(context, raw_name)
        try:
            out[name] = evaluate_value(context, value, name)
        except SubstitutionFailure as e:
            if not e.message.startswith("parameter "):
                e.message = f"parameter {name!r}: {e.message}"
                e.args = (e.message,)
            raise
        if check_clock and name == USE_SIM_TIME and not isinstance(out[name], bool):
            raise _not_a_clock_switch(context, value, out[name])
    return out


USE_SIM_TIME = "use_sim_time"


def _not_a_clock_switch(
    context: LaunchContext, value: NormalizedValue, got: Any
) -> SubstitutionFailure:
    """The error for a use_sim_time that is not a boolean.

    Every ROS node declares use_sim_time as a boolean and refuses to start with anything else
    (ros2 launch passes it on and each node dies with a type error); here it is one line that
    names the launch argument it came from, if any, so the resolver can add its declaration.
    """
    error = SubstitutionFailure(
        f"parameter {USE_SIM_TIME!r} is {got!r}, which every ROS node rejects at start-up"
        " (it must be a boolean); valid: true or false"
    )
    subs = value.subs if isinstance(value, Text) else ()
    if len(subs) == 1 and isinstance(subs[0], LaunchConfiguration):
        error.argument = perform_substitutions(context, subs[0].variable_name)
    return error


def evaluate_value(context: LaunchContext, value: NormalizedValue, name: str) -> Any:
    if isinstance(value, Plain):
        return value.value
    if isinstance(value, ParameterValue):
        return value.evaluate(context)
    if isinstance(value, Text):
        return typed_text(perform_substitutions(context, value.subs), name)
    items = [
        read_yaml(perform_substitutions(context, v), name) if isinstance(v, tuple) else v
        for v in value.items
    ]
    return uniform(items, name)


def typed_text(text: str, name: str) -> Any:
    """launch_ros's rule for a performed value: YAML, and only a scalar or a uniform list."""
    loaded = read_yaml(text if text else "''", name)
    if type(loaded) in (bool, int, float, str, bytes):
        return loaded
    if isinstance(loaded, list):
        return uniform(loaded, name)
    raise SubstitutionTypeError(
        f"parameter {name!r} is {text[:120]!r}, which YAML reads as {type(loaded).__name__}:"
        " Allowed value types are bool, int, float, str, bytes and non-empty lists of one of"
        f" bool, int, float, str{_HINT}"
    )


def read_yaml(text: str, name: str) -> Any:
    """Performed text read with YAML, as launch_ros reads a parameter's substitutions."""
    import yaml

    from mlaunch.plan.yamldata import load as load_yaml

    try:
        return load_yaml(text, f"parameter {name!r}")
    except yaml.YAMLError as e:
        first = str(e).splitlines()[0] if str(e) else type(e).__name__
        raise SubstitutionTypeError(
            f"parameter {name!r}: Unable to parse {text[:120]!r} as YAML ({first}){_HINT}"
        )


def uniform(items: Sequence[Any], name: str) -> tuple[Any, ...]:
    """A non-empty list of one type among bool, int, float, str (launch_ros's check)."""
    if items and type(items[0]) in (bool, int, float, str):
        first = type(items[0])
        if all(isinstance(i, first) for i in items):
            return tuple(items)
    kinds = ", ".join(sorted({type(i).__name__ for i in items})) or "nothing"
    raise SubstitutionTypeError(
        f"parameter {name!r} is the list {list(items)!r:.160} of {kinds}: Expected a non-empty"
        " sequence of one type (bool, int, float or str)"
    )


class ParamsArgument(Value):
    """One params argument of a node, in order: a file (``--params-file``) or a rule (``-p``)."""

    _fields = ("flag", "value", "written")
    __slots__ = _fields

    def __init__(self, flag: str, value: str, written: bool = False) -> None:
        self.flag = flag  # "--params-file" or "-p"
        self.value = value
        self.written = written  # a file mlaunch wrote (to clean up), not one the user gave


def parameter_arguments(
    context: LaunchContext,
    entries: Sequence[NormalizedEntry],
    *,
    node_key: str,
    temp_dir: str | None,
    warn: Callable[[str], None],
) -> list[ParamsArgument]:
    """The node's own parameters as arguments: one file per dict, files, ``-p`` rules.

    A params file that does not exist is skipped with a warning (``warn(message)``), as in ROS 2.
    """
    out: list[ParamsArgument] = []
    for entry in entries:
        if isinstance(entry, Parameter):
            name, value = entry.evaluate(context)
            out.append(ParamsArgument("-p", parameter_rule(name, value)))
        elif isinstance(entry, ParameterFile):
            path = str(entry.evaluate(context, temp_dir))
            if not os.path.isfile(path):
                warn(f"Parameter file path is not a file: {path} (skipped)")
                continue
            out.append(ParamsArgument("--params-file", path, written=entry.created))
        else:
            path = write_params_file(node_key, evaluate_dict(context, entry), temp_dir)
            out.append(ParamsArgument("--params-file", path, written=True))
    return out


def parameter_rule(name: str, value: Any) -> str:
    """``name:=value`` for ``-p``, the value dumped by YAML as launch_ros does (``...`` and all).

    Text rcl would retype is quoted (see ``params_file_text``).
    """
    import yaml

    return f"{name}:={yaml.dump(_plain(value), Dumper=_dumper())}"


def global_parameter_rule(name: str, value: Any) -> str:
    """``name:=value`` for a SetParameter global: Python's str() as launch_ros (``True``).

    Deliberate difference: a list is written as a YAML flow list (``[1, 2]``); launch_ros
    writes the tuple's str() ``(1, 2)``, which the node reads as a string.
    """
    if isinstance(value, (list, tuple)):
        import yaml

        flow = yaml.dump(_plain(value), Dumper=_dumper(), default_flow_style=True, width=2**31)
        text = flow.strip()
        return f"{name}:={text}"
    return f"{name}:={value}"


# --- params files -------------------------------------------------------------------------------


def params_file_text(node_key: str, params: Mapping[str, Any]) -> str:
    """The YAML of one params file as launch_ros dumps it (keys sorted, block style).

    Deliberate fix: a text value that rcl would read as something else is single-quoted.
    PyYAML quotes what *its* resolver would retype ('true', '1.0'), but rcl also reads plain
    ``y``/``n``/``Y``/``N`` as bools and anything C's strtol/strtod accept (``1e3``, ``inf``,
    ``0x1A``, `` 5``) as numbers, so launch_ros hands the node a bool or a double where the
    launch file said text. Every other value is written byte for byte as launch_ros writes it.
    """
    document = {node_key: {"ros__parameters": _plain(dict(params))}}
    import yaml

    large = _text_size(params) > LARGE_PARAMS_TEXT
    return yaml.dump(document, Dumper=_dumper(c=large), default_flow_style=False)


# Past this much text in a node's parameters (a URDF from xacro is 0.1-50 MB) the params file is
# written by libyaml's emitter: the Python one took 58-76 s for 48 MB (libyaml: a few seconds).
# The values are the same for rcl; libyaml folds long double-quoted text (an indented URDF is
# written so) at other places. Smaller files keep PyYAML's Python emitter, launch_ros's own,
# byte for byte.
LARGE_PARAMS_TEXT = 64 * 1024


def _text_size(value: Any) -> int:
    """The characters of text in ``value`` (keys and string values), to pick the emitter."""
    if isinstance(value, str):
        return len(value)
    if isinstance(value, Mapping):
        return sum(_text_size(k) + _text_size(v) for k, v in value.items())
    if isinstance(value, (list, tuple)):
        return sum(_text_size(v) for v in value)
    return 0


def write_params_file(node_key: str, params: Mapping[str, Any], temp_dir: str | None) -> str:
    """Write one params file (``launch_params_XXXXXXXX``) in ``temp_dir``; return its path."""
    return write_temp(PARAMS_FILE_PREFIX, params_file_text(node_key, params), temp_dir)


def _plain(value: Any) -> Any:
    """Tuples as lists (plain YAML any reader accepts); text values marked for rcl quoting."""
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, str):
        return _TextValue(value)
    return value


class _TextValue(str):
    """A text parameter value (not a key): quoted when rcl would not read it as text."""


# rcl's bool words (YAML 1.1 style, in three spellings each, plus y/n).
_RCL_BOOLS = frozenset(
    {"Y", "y", "N", "n"}
    | {v for w in ("yes", "true", "on", "no", "false", "off") for v in (w, w.title(), w.upper())}
)
_C_SPACE = r"[ \t\n\v\f\r]*"
# What C's strtol(base 0) or strtod consume completely (after leading white space).
_RCL_NUMBER = re.compile(
    _C_SPACE
    + r"[+-]?(?:"
    + r"0[xX](?:[0-9a-fA-F]+\.?[0-9a-fA-F]*|\.[0-9a-fA-F]+)(?:[pP][+-]?[0-9]+)?"
    + r"|(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?"
    + r"|inf(?:inity)?|nan(?:\([0-9A-Za-z_]*\))?"
    + r")",
    re.IGNORECASE,
)


def rcl_reads_as_text(text: str) -> bool:
    """Whether rcl's params parser keeps a plain (unquoted) YAML scalar as a string."""
    return text not in _RCL_BOOLS and _RCL_NUMBER.fullmatch(text) is None


_DUMPERS: dict[bool, Any] = {}  # the dumper classes (Python, C), once built


def _dumper(*, c: bool = False) -> Any:
    """yaml.Dumper (as launch_ros uses) that quotes text values rcl would retype; with ``c``,
    the same on libyaml's emitter (yaml.CDumper) where PyYAML has it.

    Built on first use: PyYAML is imported only by launches that write parameters.
    """
    import yaml

    base = getattr(yaml, "CDumper", yaml.Dumper) if c else yaml.Dumper
    c = base is not yaml.Dumper
    if c in _DUMPERS:
        return _DUMPERS[c]

    def represent_text(dumper: yaml.Dumper, data: _TextValue) -> yaml.ScalarNode:
        style = None if rcl_reads_as_text(data) else "'"
        return dumper.represent_scalar("tag:yaml.org,2002:str", str(data), style=style)

    class ParamsDumper(base):  # type: ignore[misc,valid-type]
        pass

    ParamsDumper.add_representer(_TextValue, represent_text)
    _DUMPERS[c] = ParamsDumper
    return ParamsDumper


__all__ = [
    "Items",
    "ParamsArgument",
    "Plain",
    "Text",
    "evaluate_dict",
    "evaluate_value",
    "global_parameter_rule",
    "normalize_dict",
    "normalize_parameters",
    "parameter_arguments",
    "parameter_rule",
    "params_file_text",
    "write_params_file",
]
