"""Class checks launch's own code and extensions use (``is_a``, ``is_a_subclass``)."""

from __future__ import annotations

import inspect
from typing import Any


def isclassinstance(obj: Any) -> bool:
    """Whether ``obj`` is an instance of some class (every Python object is)."""
    return hasattr(obj, "__class__")


def is_a(obj: Any, entity_type: type) -> bool:
    """``isinstance`` that refuses a non-class ``entity_type`` with RuntimeError, as launch."""
    if not isclassinstance(obj):
        raise RuntimeError(f"obj '{obj}' is not a class instance")
    if not inspect.isclass(entity_type):
        raise RuntimeError(f"entity_type '{obj}' is not a class")
    return isinstance(obj, entity_type)


def is_a_subclass(obj: Any, entity_type: type) -> bool:
    """Whether ``obj`` is an instance of ``entity_type`` or a class derived from it."""
    if is_a(obj, entity_type):
        return True
    try:
        return issubclass(obj, entity_type)
    except TypeError:
        return False
