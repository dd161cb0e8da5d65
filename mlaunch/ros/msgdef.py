"""A ROS 2 message's full definition as rosbag2 writes it into an MCAP schema (``ros2msg``).

The type's own ``.msg`` text, then each type it uses (recursively, once each) after a line of 80
``=`` and ``MSG: pkg/Type``: what Foxglove and rosbag2 read to decode the CDR bytes of a
recording. The ``.msg`` files are the packages' (``share/<pkg>/msg/<Type>.msg``), found in the
ament prefixes and in the running Python's prefix (where the ROS wheels install them).
"""

from __future__ import annotations

import os
import re
import sys

TYPE_CHECKING = False  # mypy reads this as typing.TYPE_CHECKING; typing costs ~3 ms
if TYPE_CHECKING:
    from collections.abc import Mapping

PRIMITIVES = frozenset(
    {
        "bool", "byte", "char", "float32", "float64", "int8", "uint8", "int16", "uint16",
        "int32", "uint32", "int64", "uint64", "string", "wstring",
    }
)  # fmt: skip
SEPARATOR = "=" * 80
_FIELD = re.compile(r"^\s*([A-Za-z][\w/]*)(?:<=\d+)?(?:\[[^\]]*\])?\s+\w+")


class MessageDefinitionError(LookupError):
    """A type's .msg file cannot be found (its package is not installed with its share folder)."""


def definition(type_name: str, environ: Mapping[str, str] | None = None) -> str:
    """The full definition of ``type_name`` ('sensor_msgs/msg/LaserScan' or 'pkg/Type')."""
    package, name = split(type_name)
    prefixes = _prefixes(os.environ if environ is None else environ)
    top = _read(package, name, prefixes)
    parts = [top.rstrip("\n")]
    seen = {f"{package}/{name}"}
    todo = [(package, t) for t in used_types(top)]
    while todo:
        owner, used = todo.pop(0)
        dep_package, dep_name = split(used) if "/" in used else (owner, used)
        key = f"{dep_package}/{dep_name}"
        if key in seen:
            continue
        seen.add(key)
        text = _read(dep_package, dep_name, prefixes)
        parts.append(f"{SEPARATOR}\nMSG: {key}\n{text.rstrip(chr(10))}")
        todo += [(dep_package, t) for t in used_types(text)]
    return "\n".join(parts) + "\n"


def split(type_name: str) -> tuple[str, str]:
    """('sensor_msgs', 'LaserScan') from 'sensor_msgs/msg/LaserScan' or 'sensor_msgs/LaserScan'."""
    pieces = type_name.strip("/").split("/")
    if len(pieces) == 3 and pieces[1] == "msg":
        return pieces[0], pieces[2]
    if len(pieces) == 2:
        return pieces[0], pieces[1]
    raise MessageDefinitionError(f"{type_name!r} is not a message type like 'pkg/msg/Type'")


def used_types(text: str) -> list[str]:
    """The non-primitive field types of a .msg text, in order (constants and comments skipped)."""
    found = []
    for line in text.splitlines():
        line = line.split("#", 1)[0]
        match = _FIELD.match(line)
        if match is None or "=" in line.split(None, 2)[-1][:1]:
            continue
        words = line.split()
        if len(words) >= 3 and words[2].startswith("="):
            continue  # TYPE NAME = VALUE: a constant
        if "=" in words[1]:
            continue  # TYPE NAME=VALUE
        base = match.group(1)
        if base not in PRIMITIVES and base not in found:
            found.append(base)
    return found


def _prefixes(environ: Mapping[str, str]) -> list[str]:
    prefixes = [p for p in environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p]
    return [*prefixes, sys.prefix]


def _read(package: str, name: str, prefixes: list[str]) -> str:
    for prefix in prefixes:
        path = os.path.join(prefix, "share", package, "msg", f"{name}.msg")
        try:
            with open(path, encoding="utf-8") as f:
                return f.read()
        except OSError:
            continue
    raise MessageDefinitionError(
        f"no definition of {package}/msg/{name}: share/{package}/msg/{name}.msg is in none of"
        f" {', '.join(prefixes)}"
    )
