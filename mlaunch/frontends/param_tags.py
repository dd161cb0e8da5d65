"""The ``param`` tag of YAML/XML nodes and ``set_parameter``: names, nesting and typed values.

ROS 2 types a parameter by its ``type`` attribute, else guesses it as YAML would; a value that
does not fit its type is an error at load time, with the file and line of the attribute.
"""

from __future__ import annotations

from mlaunch.frontends.element import Attr, Element
from mlaunch.frontends.fields import Value, as_key, required_text
from mlaunch.launch.substitution import Substitution, TextSubstitution
from mlaunch.launch.substitutions.boolean_substitution import to_bool
from mlaunch.plan.errors import MlaunchError

TYPE_CHECKING = False  # mypy reads this as typing.TYPE_CHECKING; typing costs ~3 ms
if TYPE_CHECKING:
    from typing import Any


def _descriptions() -> Any:
    import mlaunch.launch_ros.parameter_descriptions as descriptions

    return descriptions


def parameter_item(p: Element) -> Any:
    """One top-level ``param`` of a node: a ParameterFile (``from``) or its own dict."""
    for name in ("name", "value", "type", "value-sep"):
        p.has(name)
    source = p.text("from")
    allow = p.flag("allow_substs")
    if source is not None:
        if "name" in p.attrs:
            raise p.error("'from' and 'name' cannot both be given", p.attrs["name"])
        p.finish()
        return _descriptions().ParameterFile(source, allow_substs=False if allow is None else allow)
    if allow is not None:
        raise p.error("'allow_substs' is only valid with 'from'", p.attrs["allow_substs"])
    if "name" not in p.attrs:
        raise p.error("a param needs 'name' (with 'value' or nested params) or 'from'")
    return dict(_parameter_entries(p, None))


def _parameter_entries(p: Element, prefix: Value | None) -> list[tuple[Any, Any]]:
    """``name: value`` entries of a param; nested params give dotted names (``a.b.c``)."""
    name = required_text(p, "name")
    key = name if prefix is None else _join(prefix, name)
    nested = p.subentities("param")
    entries: list[tuple[Any, Any]] = []
    if nested:
        for what in ("value", "type", "value-sep"):
            if what in p.attrs:
                raise p.error(f"a param with nested params cannot have {what!r}", p.attrs[what])
        for child in nested:
            entries += _parameter_entries(child, key)
    else:
        if "value" not in p.attrs:
            raise p.error(f"param {_show(name)} needs 'value' (or nested params)")
        entries.append((as_key(key), parameter_value(p, typed=True)))
    p.finish()
    return entries


def _join(prefix: Value, name: Value) -> Value:
    if isinstance(prefix, str) and isinstance(name, str):
        return f"{prefix}.{name}"
    left = [prefix] if isinstance(prefix, str) else list(prefix)
    right = [name] if isinstance(name, str) else list(name)
    return [*left, ".", *right]


def _show(value: Value) -> str:
    return repr(value) if isinstance(value, str) else "(with substitutions)"


# type= names -> (element type, is a list); "yaml" and no type guess as ROS 2 does.
PARAM_TYPES: dict[str, tuple[type | None, bool]] = {
    "str": (str, False),
    "bool": (bool, False),
    "int": (int, False),
    "float": (float, False),
    "list_of_str": (str, True),
    "list_of_bool": (bool, True),
    "list_of_int": (int, True),
    "list_of_float": (float, True),
    "yaml": (None, False),
}


def parameter_value(p: Element, *, typed: bool) -> Any:
    """The ``value`` of a param (a ParameterValue) or of set_parameter (the plain value)."""
    type_name = p.literal("type") if typed else None
    if type_name is not None and type_name not in PARAM_TYPES:
        raise p.error(
            f"type={type_name!r} is not a parameter type; valid: {', '.join(PARAM_TYPES)}",
            p.attrs["type"],
        )
    element, is_list = PARAM_TYPES[type_name or "yaml"]
    sep = p.literal("value-sep")
    attr = p.attr("value", required=True)
    assert attr is not None
    # A node param's YAML string (quoted, or text YAML reads as text) stays text in launch_ros;
    # set_parameter's value is read as a substitution and typed as YAML.
    keep_text = typed and not isinstance(attr.value, str)
    if not typed and sep is None and _is_text(attr.value):
        # launch_ros keeps it as a substitution: SetParameter.value is that, and YAML types the
        # performed text when the action runs.
        text = p.template(attr, p.scalar_text(attr, "value"))
        return [TextSubstitution(text=text)] if isinstance(text, str) else text
    value = _typed_value(p, attr, element, is_list, sep, keep_text=keep_text)
    if not typed:
        return value
    value_type: Any = None
    if element is not None:
        import typing  # only here: typing costs ~3 ms on every YAML/XML launch

        value_type = typing.List[element] if is_list else element  # type: ignore[valid-type]  # noqa: UP006
    return _descriptions().ParameterValue(value, value_type=value_type)


def _typed_value(
    p: Element, attr: Attr, element: type | None, is_list: bool, sep: str | None, *, keep_text: bool
) -> Any:
    node = attr.value
    kind = type(node).__name__
    if kind == "SequenceNode":  # a YAML list keeps its items' YAML types
        items = [p.yaml_construct(item) for item in node.value]
        return _uniform_list(p, attr, [_yaml_item(p, attr, item, element) for item in items])
    if kind == "MappingNode":
        raise p.error("a parameter value cannot be a map; nest params instead", attr)
    if not isinstance(node, str) and node.tag != "tag:yaml.org,2002:str":
        if node.tag == "tag:yaml.org,2002:null":
            raise p.error('the parameter value is empty (null); write "" for empty text', attr)
        native = p.yaml_construct(node)  # a YAML number or bool keeps its type
        return _coerce(p, attr, native, element, is_list) if element is not None else native
    text = p.scalar_text(attr, "value")
    if sep is not None:
        if not sep:
            raise p.error("value-sep is empty", p.attrs["value-sep"])
        pieces = [_text_item(p, attr, piece, element) for piece in text.split(sep)]
        return _uniform_list(p, attr, pieces)
    if "$(" in text:
        return p.template(attr, text)
    if keep_text and element is None:
        return _unescaped(p, attr, text)
    return _unescaped(p, attr, _coerce(p, attr, text, element, is_list))


def _is_text(node: Any) -> bool:
    """An XML attribute, or a YAML scalar written as a string."""
    return isinstance(node, str) or (
        type(node).__name__ == "ScalarNode" and node.tag == "tag:yaml.org,2002:str"
    )


def _yaml_item(p: Element, attr: Attr, item: Any, element: type | None) -> Any:
    if isinstance(item, str) and "$(" in item:
        return p.template(attr, item)
    if isinstance(item, (dict, list)) or item is None:
        raise p.error(f"a list parameter holds plain values, not {item!r}", attr)
    typed = _coerce(p, attr, item, element, False) if element is not None else item
    return _unescaped(p, attr, typed)


def _text_item(p: Element, attr: Attr, piece: str, element: type | None) -> Any:
    """One piece of a value split by value-sep: typed by ``type``, else guessed."""
    if "$(" in piece:
        return p.template(attr, piece)
    if element is None:
        return _unescaped(p, attr, _guess(piece))
    return _unescaped(p, attr, _coerce(p, attr, piece, element, False))


def _unescaped(p: Element, attr: Attr, value: Any) -> Any:
    """The value with each text in it read as launch_ros reads it after typing the value: as
    substitutions, so its escapes count (``\\'2\\'`` is the text ``'2'``, ``\\\\`` one backslash).
    A text with no backslash (nor ``$(``, handled before) is the same either way."""
    if isinstance(value, str) and "\\" in value:
        return p.template(attr, value)
    if isinstance(value, list):
        return [_unescaped(p, attr, item) for item in value]
    return value


def _uniform_list(p: Element, attr: Attr, items: list[Any]) -> list[Any]:
    """ROS 2 parameters are uniform lists (ints and floats may mix, as floats)."""
    static = [i for i in items if not isinstance(i, (list, Substitution))]
    if static and not _uniform(static):
        kinds = sorted({type(i).__name__ for i in static})
        raise p.error(
            f"a list parameter must hold one type, this one mixes {', '.join(kinds)}: {static!r}",
            attr,
        )
    return items


def _guess(text: str) -> Any:
    """ROS 2's type guess for an untyped value: YAML int, float, bool, str or uniform list, else
    the text as written. YAML's own reading of a string counts: ``'7'`` is the text 7."""
    import yaml

    from mlaunch.plan.yamldata import load as load_yaml

    try:
        value = load_yaml(text)
    except yaml.YAMLError:
        return text
    if isinstance(value, (bool, int, float, str)):
        return value
    if isinstance(value, list) and value and _uniform(value):
        return value
    return text


def _uniform(items: list[Any]) -> bool:
    kinds = {bool if isinstance(i, bool) else type(i) for i in items}
    return kinds <= {int, float} or (len(kinds) == 1 and kinds <= {bool, int, float, str})


def _coerce(p: Element, attr: Attr, value: Any, element: type | None, is_list: bool) -> Any:
    """A value forced to the param's ``type``; a wrong one is an error at load time."""
    if element is None:
        return _guess(value) if isinstance(value, str) else value
    if is_list:
        items = _guess_list(p, attr, value)
        return [_coerce(p, attr, item, element, False) for item in items]
    try:
        return _scalar(value, element)
    except ValueError:
        raise p.error(f"parameter value {value!r} is not of type {element.__name__}", attr)


def _guess_list(p: Element, attr: Attr, value: Any) -> list[Any]:
    if isinstance(value, list):
        return value
    import yaml

    from mlaunch.plan.yamldata import load as load_yaml

    try:
        loaded = load_yaml(value) if isinstance(value, str) else value
    except yaml.YAMLError:
        loaded = None
    if not isinstance(loaded, list):
        raise p.error(
            f"parameter value {value!r} is not a list; write [a, b] or split it with value-sep",
            attr,
        )
    return loaded


def _scalar(value: Any, element: type) -> Any:
    if element is str:
        return value if isinstance(value, str) else _text(value)
    if element is bool:
        if isinstance(value, bool):
            return value
        if isinstance(value, str):
            try:
                return to_bool(value, "value")
            except MlaunchError:
                pass
        raise ValueError(value)
    if isinstance(value, bool):
        raise ValueError(value)
    if element is int:
        if isinstance(value, int):
            return value
        if isinstance(value, str):
            guessed = _guess(value.strip())
            if isinstance(guessed, int) and not isinstance(guessed, bool):
                return guessed
        raise ValueError(value)
    if isinstance(value, (int, float)):
        return float(value)
    guessed = _guess(value.strip()) if isinstance(value, str) else None
    if isinstance(guessed, (int, float)) and not isinstance(guessed, bool):
        return float(guessed)
    raise ValueError(value)


def _text(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    return str(value)
