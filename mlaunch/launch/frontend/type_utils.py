"""``launch.frontend.type_utils``: the type helpers markup implementations share."""

from __future__ import annotations

from mlaunch.launch.frontend.coercion import is_typing_list
from mlaunch.launch.frontend.entity import Entity

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING
if TYPE_CHECKING:
    from typing import Any


def check_is_list_entity(data_type: Any) -> bool:
    """Whether ``data_type`` is ``List[E]`` for an Entity class E (sub-entities, not a value)."""
    if not is_typing_list(data_type):
        return False
    args: tuple[Any, ...] = getattr(data_type, "__args__", None) or ()
    return bool(args) and isinstance(args[0], type) and issubclass(args[0], Entity)


def get_data_type_from_identifier(type_identifier: str) -> Any:
    """The data type a ``type`` attribute names (str, bool, ..., list_of_int, yaml)."""
    from typing import List  # noqa: UP035 - upstream's values are typing.List[...]

    mapping: dict[str, Any] = {
        "str": str,
        "bool": bool,
        "float": float,
        "int": int,
        "list_of_str": List[str],  # noqa: UP006
        "list_of_bool": List[bool],  # noqa: UP006
        "list_of_float": List[float],  # noqa: UP006
        "list_of_int": List[int],  # noqa: UP006
        "yaml": None,
    }
    if type_identifier not in mapping:
        raise ValueError(f"Got invalid type identifier '{type_identifier}'")
    return mapping[type_identifier]


__all__ = ["check_is_list_entity", "get_data_type_from_identifier"]
