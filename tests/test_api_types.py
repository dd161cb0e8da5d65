"""launch.utilities.type_utils: typed values given as text or substitutions (issue 25, gap 4)."""

from __future__ import annotations

from typing import List  # noqa: UP035 (the spelling launch files pass)

import pytest

from mlaunch.launch.launch_context import LaunchContext
from mlaunch.launch.substitutions import LaunchConfiguration, TextSubstitution
from mlaunch.launch.utilities import type_utils as tu


def test_types_are_extracted_and_unknown_ones_refused() -> None:
    assert tu.extract_type(List[int]) == (int, True)  # noqa: UP006 (launch's spelling)
    assert tu.extract_type(bool) == (bool, False)
    with pytest.raises(ValueError, match="Unrecognized data type"):
        tu.extract_type(dict)
    assert tu.is_typing_list(List) and tu.is_typing_list(List[int])  # noqa: UP006
    assert not tu.is_typing_list(list) and not tu.is_typing_list(int)


def test_text_is_coerced_with_yaml_rules() -> None:
    assert tu.coerce_to_type("1", bool) is True
    assert tu.coerce_to_type("off", bool) is False
    assert tu.coerce_to_type("2", float) == 2.0
    assert tu.coerce_to_type("[1, 2]", List[int]) == [1, 2]  # noqa: UP006
    assert tu.coerce_to_type("{a: 1}", str) == "{a: 1}"
    with pytest.raises(ValueError):
        tu.coerce_to_type("[1, 'a']", List[int])  # noqa: UP006
    with pytest.raises(ValueError):
        tu.coerce_to_type("maybe", bool)
    assert tu.coerce_to_type("maybe", bool, can_be_str=True) == "maybe"
    with pytest.raises(TypeError):
        tu.coerce_to_type(1, int)  # type: ignore[arg-type]


def test_lists_of_text_and_uniformity() -> None:
    assert tu.get_typed_value(["1", "2"], List[float]) == [1.0, 2.0]  # noqa: UP006
    with pytest.raises(TypeError):
        tu.get_typed_value(["1"], int)
    with pytest.raises(ValueError):
        tu.coerce_list(["1", "a"])
    assert tu.is_instance_of_valid_type([1, "a"], can_be_str=True)
    assert not tu.is_instance_of_valid_type([1, "a"])


def test_normalized_values_perform_to_their_type() -> None:
    context = LaunchContext()
    context.launch_configurations["n"] = "3"
    value = tu.normalize_typed_substitution([1, LaunchConfiguration("n")], List[int])  # noqa: UP006
    assert value[0] == 1 and tu.is_normalized_substitution(value[1])
    assert tu.perform_typed_substitution(context, value, List[int]) == [1, 3]  # noqa: UP006
    single = tu.normalize_typed_substitution(["x", TextSubstitution(text="1")], None)
    assert tu.perform_typed_substitution(context, single, None) == "x1"
    with pytest.raises(TypeError):
        tu.normalize_typed_substitution([1, 2], int)
    with pytest.raises(TypeError):
        tu.normalize_typed_substitution([1, "a"], List[int])  # noqa: UP006
    assert tu.normalize_typed_substitution([1, 2.5], None) == [1.0, 2.5]
