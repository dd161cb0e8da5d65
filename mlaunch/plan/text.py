"""How plan values are written for people (``--print``) and as JSON data (``--format json``).

Shared by the plan's writers (mlaunch.resolve.describe, mlaunch.resolve.plan_json) and by the
steps of extensions that describe themselves (a composable node load).
"""

from __future__ import annotations

import math
import os


def value_text(value: object) -> str:
    if isinstance(value, str):
        if len(value) > 80 or "\n" in value:
            first = value.strip().splitlines()[0] if value.strip() else ""
            return f"<string, {len(value)} chars: {shorten(first, 50)}>"
        return repr(value)
    if isinstance(value, bool):
        return "true" if value else "false"
    return repr(value)


def shorten(text: str, limit: int) -> str:
    text = text.replace("\n", "\\n")
    if len(text) <= limit:
        return text
    return f"{text[: limit - 20]}... <{len(text)} chars>"


def rel(path: str) -> str:
    if not path:
        return ""
    try:
        rel = os.path.relpath(path)
    except ValueError:
        return path
    return rel if not rel.startswith("../../") else path


def json_safe(value: object) -> object:
    """YAML data as JSON data: non-finite floats as YAML spells them, other scalars (dates,
    bytes) as text, keys as text."""
    if isinstance(value, dict):
        return {str(k): json_safe(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [json_safe(v) for v in value]
    if isinstance(value, float) and not math.isfinite(value):
        return ".nan" if math.isnan(value) else (".inf" if value > 0 else "-.inf")
    if value is None or isinstance(value, (bool, int, float, str)):
        return value
    return str(value)
