"""Remap rules as launch_ros stores them: (from, to), each a tuple of substitutions."""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from typing import Any

from mlaunch.launch.substitution import Substitution
from mlaunch.launch.utilities.ensure_argument_type_impl import ensure_argument_type
from mlaunch.launch.utilities.normalize_to_list_of_substitutions_impl import (
    normalize_to_list_of_substitutions,
)

RemapRule = tuple[tuple[Substitution, ...], tuple[Substitution, ...]]


def normalize_remap_rule(remap_rule: Any) -> RemapRule:
    """A (from, to) pair of text or substitutions, normalized; TypeError for anything else."""
    ensure_argument_type(remap_rule, tuple, "remap_rule")
    if len(remap_rule) != 2:
        raise TypeError(f"remap_rule must be a tuple of length 2, got length {len(remap_rule)}")
    return (
        tuple(normalize_to_list_of_substitutions(remap_rule[0])),
        tuple(normalize_to_list_of_substitutions(remap_rule[1])),
    )


def normalize_remap_rules(remap_rules: Iterable[Any]) -> Iterator[RemapRule]:
    """Each rule normalized, lazily (as launch_ros's generator)."""
    yield from map(normalize_remap_rule, remap_rules)
