"""The value types markup attributes are read as, and the coercion of XML text to them
(the rules of upstream's ``launch.utilities.type_utils``, which ``launch.frontend`` uses).

Allowed: str, int, float, bool and uniform lists of them (``List[int]`` ...); ``None`` means
"whatever YAML reads the text as". ``can_be_str`` keeps a value as text when it cannot be
coerced (it may hold substitutions, performed later).
"""

from __future__ import annotations

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING
if TYPE_CHECKING:
    from typing import Any

SCALAR_TYPES = (int, float, bool, str)


def is_typing_list(data_type: Any) -> bool:
    """Whether ``data_type`` is ``typing.List`` or a subscription of a list (``List[int]``,
    ``list[int]``); the bare ``list`` class is not, as in launch."""
    return getattr(data_type, "__origin__", None) is list


def extract_type(data_type: Any) -> tuple[type, bool]:
    """(the scalar type, whether it is a list of it); ValueError for any other type."""
    scalar, is_list = data_type, False
    args = getattr(data_type, "__args__", None)
    if is_typing_list(data_type) and args:
        scalar, is_list = args[0], True
    if scalar not in SCALAR_TYPES:
        raise ValueError(f"Unrecognized data type: {data_type}")
    return scalar, is_list


def is_instance_of_valid_type(value: Any, *, can_be_str: bool = False) -> bool:
    """Whether ``value`` is an allowed scalar, or a uniform list of one (strings mixed in when
    ``can_be_str``)."""
    if isinstance(value, list):
        member = next((type(x) for x in value if type(x) is not str), str)
        if member not in SCALAR_TYPES:
            return False
        valid = (member, str) if can_be_str else (member,)
        return all(isinstance(x, valid) for x in value)
    return isinstance(value, SCALAR_TYPES)


def is_instance_of(value: Any, data_type: Any = None, *, can_be_str: bool = False) -> bool:
    """Whether ``value`` is a ``data_type`` (any allowed type when None)."""
    if data_type is None:
        return is_instance_of_valid_type(value, can_be_str=can_be_str)
    scalar, is_list = extract_type(data_type)
    valid: tuple[type, ...] = (str, scalar) if can_be_str else (scalar,)
    if not is_list:
        return isinstance(value, valid)
    return isinstance(value, list) and all(isinstance(x, valid) for x in value)


def _as_yaml(value: str, can_be_str: bool, message: str) -> Any:
    """The text read as a YAML value (empty text stays empty)."""
    if not value:
        return value
    from mlaunch.plan.errors import MlaunchError
    from mlaunch.plan.yamldata import load as load_yaml

    try:
        output = load_yaml(value)
    except MlaunchError:
        raise  # past a bound: an alias bomb is not text to fall back to
    except Exception as err:
        if can_be_str:
            return value
        raise ValueError(f"{message}: yaml.safe_load() failed\n{err}") from err
    if not is_instance_of_valid_type(output, can_be_str=can_be_str):
        raise ValueError(f"{message}: output type is not allowed, got {type(output)}")
    return output


def coerce_to_type(value: str, data_type: Any = None, *, can_be_str: bool = False) -> Any:
    """The text ``value`` as a ``data_type``; ValueError when it is not one."""
    if not isinstance(value, str):
        raise TypeError(f"coerce_to_type: 'value' must be a str, got {type(value).__name__}")
    if data_type is None:
        return _as_yaml(value, can_be_str, f"Failed to convert '{value}' using yaml rules")
    scalar, is_list = extract_type(data_type)
    valid: tuple[type, ...] = (str, scalar) if can_be_str else (scalar,)
    if is_list:
        message = f"Cannot convert value '{value}' to a list of '{valid}'"
        output = _as_yaml(value, can_be_str, message)
        if not isinstance(output, list) or not all(isinstance(x, valid) for x in output):
            raise ValueError(message)
        return output
    if scalar is str:
        return value
    if scalar in (int, float):
        try:
            return scalar(value)
        except ValueError:
            if can_be_str:
                return value
            raise
    # bool: '1' and '0' read as true and false
    text = {"1": "true", "0": "false"}.get(value, value)
    output = _as_yaml(text, can_be_str, f"Failed to convert '{value}' to '{scalar}'")
    if isinstance(output, valid):
        return output
    raise ValueError(f"Cannot convert value '{value}' to '{scalar}'")


def get_typed_value(value: str | list[str], data_type: Any, *, can_be_str: bool = False) -> Any:
    """The text (or list of texts) coerced to ``data_type``."""
    if not isinstance(value, list):
        return coerce_to_type(value, data_type, can_be_str=can_be_str)
    scalar: Any = None
    if data_type is not None:
        scalar, is_list = extract_type(data_type)
        if not is_list:
            raise TypeError(f"Cannot convert input '{value}' of type '{type(value)}' to '{scalar}'")
    output = [coerce_to_type(item, scalar, can_be_str=can_be_str) for item in value]
    if not is_instance_of_valid_type(output, can_be_str=can_be_str):
        raise ValueError(f"cannot convert value to {data_type}. Got value=`{value}`")
    return output
