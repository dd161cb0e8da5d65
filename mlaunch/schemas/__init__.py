"""The JSON Schemas of what mlaunch writes as data, shipped with the package.

``plan-1.json`` describes ``mlaunch FILE --print --format json`` (docs/plan-json.md). mlaunch
never validates its own output at run time (no validator is a dependency); tools and the tests
read the schema from here.
"""

from __future__ import annotations

import os

PLAN_SCHEMA = os.path.join(os.path.dirname(os.path.abspath(__file__)), "plan-1.json")


def load_plan_schema() -> dict[str, object]:
    """The plan document's JSON Schema, parsed."""
    import json

    with open(PLAN_SCHEMA, encoding="utf-8") as f:
        schema: dict[str, object] = json.load(f)
    return schema
