"""``expose_action`` / ``expose_substitution``: the tables third-party tags and substitutions
register in, and the two functions that build from them.

A parse method takes ``(entity, parser)`` (an action) or the list of arguments, each a list of
substitutions (a substitution), and returns ``(type, kwargs)``; the object is ``type(**kwargs)``.
mlaunch's readers build their own tags from their own table and look here for any other tag or
``$(name)``.
"""

from __future__ import annotations

import functools
import types

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING
if TYPE_CHECKING:
    from collections.abc import Callable, Iterable
    from typing import Any

    from mlaunch.launch.action import Action
    from mlaunch.launch.frontend.entity import Entity
    from mlaunch.launch.frontend.parser import Parser
    from mlaunch.launch.substitution import Substitution

action_parse_methods: dict[str, Any] = {}
substitution_parse_methods: dict[str, Any] = {}


def instantiate_action(entity: Entity, parser: Parser) -> Action:
    """The action the parse method registered for ``entity.type_name`` builds."""
    if entity.type_name not in action_parse_methods:
        raise RuntimeError(f"Unrecognized entity of the type: {entity.type_name}")
    action_type, kwargs = action_parse_methods[entity.type_name](entity, parser)
    action: Action = action_type(**kwargs)
    return action


def instantiate_substitution(type_name: str, args: Iterable[Any] | None = None) -> Substitution:
    """The substitution the parse method registered for ``$(type_name ...)`` builds."""
    if type_name not in substitution_parse_methods:
        raise RuntimeError(f"Unknown substitution: {type_name}")
    subst_type, kwargs = substitution_parse_methods[type_name]([] if args is None else args)
    substitution: Substitution = subst_type(**kwargs)
    return substitution


def __expose_impl(
    name: str, parse_methods_map: dict[str, Any], exposed_type: str
) -> Callable[[Any], Any]:
    """A decorator storing the parse method of a class (its ``parse`` classmethod) or a function
    under ``name`` in ``parse_methods_map``; an action's is wrapped so that whatever the method
    left unread is an error. Another method under the same name is a RuntimeError.
    """

    def expose_impl_decorator(exposed: Any) -> Any:
        found = _parse_method_of(exposed, name, exposed_type)
        if name in parse_methods_map and _unwrapped(parse_methods_map[name]) != found:
            raise RuntimeError(
                f"Two {exposed_type} parsing methods exposed with the same name: [{name}]."
            )
        if exposed_type == "action":
            parse_methods_map[name] = _checked(found)
        else:
            parse_methods_map[name] = found
        return exposed

    return expose_impl_decorator


def _parse_method_of(exposed: Any, name: str, exposed_type: str) -> Any:
    if isinstance(exposed, type):
        # A classmethod read from its class is a bound method; a staticmethod is a function.
        method = getattr(exposed, "parse", None)
        if not isinstance(method, types.MethodType):
            raise RuntimeError(
                "Did not find a class method called 'parse' in the class being decorated."
            )
        return method
    if isinstance(exposed, types.FunctionType):
        return exposed
    raise RuntimeError(
        f"Exposed {exposed_type} parser for {name} is not a callable or a class"
        " containing a parse method"
    )


def _checked(parse: Any) -> Any:
    @functools.wraps(parse)
    def wrapper(entity: Entity, parser: Parser) -> Any:
        result = parse(entity, parser)
        entity.assert_entity_completely_parsed()
        return result

    return wrapper


def _unwrapped(method: Any) -> Any:
    return getattr(method, "__wrapped__", method)


def expose_substitution(name: str) -> Callable[[Any], Any]:
    """Register the decorated class's ``parse`` (or the function) for ``$(name ...)``."""
    return __expose_impl(name, substitution_parse_methods, "substitution")


def expose_action(name: str) -> Callable[[Any], Any]:
    """Register the decorated class's ``parse`` (or the function) for the tag ``name``."""
    return __expose_impl(name, action_parse_methods, "action")


__all__ = [
    "action_parse_methods",
    "expose_action",
    "expose_substitution",
    "instantiate_action",
    "instantiate_substitution",
    "substitution_parse_methods",
]
