"""The JSON Schemas of what mlaunch writes as data, shipped with the package.

``plan-1.json`` describes ``mlaunch FILE --print --format json``, ``arguments-1.json``
``mlaunch FILE --show-args --format json`` (docs/plan-json.md). mlaunch
never validates its own output at run time (no validator is a dependency); tools and the tests
read the schema from here.
"""

from __future__ import annotations

import os

HERE = os.path.dirname(os.path.abspath(__file__))
PLAN_SCHEMA = os.path.join(HERE, "plan-1.json")
ARGUMENTS_SCHEMA = os.path.join(HERE, "arguments-1.json")


def load_schema(path: str) -> dict[str, object]:
    """A JSON Schema of this folder, parsed."""
    import json

    with open(path, encoding="utf-8") as f:
        schema: dict[str, object] = json.load(f)
    return schema


def load_plan_schema() -> dict[str, object]:
    """The plan document's JSON Schema, parsed."""
    return load_schema(PLAN_SCHEMA)
