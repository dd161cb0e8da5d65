"""``mlaunch convert``: a ROS 1 roslaunch file written out as an idiomatic ROS 2 launch file.

    mlaunch convert old.launch [--to py|yaml|xml] [-o FILE]

The file is read by the roslaunch frontend (``mlaunch.ros1.reading.read``), which maps it
to the ROS 2 description it becomes; the writers only *write* that description, in Python
(``to_python``: launch / launch_ros classes), YAML (``to_yaml``: launch_yaml) or XML
(``to_xml``: launch_xml). Because running the ROS 1
file builds the very same description, the converted file resolves to the same plan. Every
warning of the mapping is written as a comment where it applies; a node that cannot run here is
kept, commented out, with the reason.
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Callable, Sequence
from typing import Any

from mlaunch.convert.to_python import PythonWriter
from mlaunch.convert.to_xml import XmlWriter
from mlaunch.convert.to_yaml import YamlWriter
from mlaunch.convert.writing import FORMATS, ConversionError, Source
from mlaunch.plan.argparser import ArgumentParser
from mlaunch.plan.errors import LaunchFileError, UsageError
from mlaunch.ros1.reading import read

WRITERS: dict[str, Callable[[Source], Any]] = {
    "py": PythonWriter,
    "yaml": YamlWriter,
    "xml": XmlWriter,
}


def convert(path: str, fmt: str, output: str | None = None) -> str:
    """The ROS 2 launch file (text) the roslaunch file at ``path`` becomes."""
    if fmt not in WRITERS:
        raise UsageError(f"format {fmt!r} is not one of {', '.join(WRITERS)}")
    source = Source(os.path.abspath(path), output, fmt)
    items = read(source.path, converting=True)
    return str(WRITERS[fmt](source).write(items))


def build_parser() -> argparse.ArgumentParser:
    parser = ArgumentParser(
        prog="mlaunch convert",
        description="Convert a ROS 1 roslaunch XML file to a ROS 2 launch file that resolves to"
        " the same plan as running the ROS 1 file with mlaunch.",
    )
    parser.add_argument("file", help="the ROS 1 .launch file")
    parser.add_argument(
        "--to",
        choices=sorted(WRITERS),
        help="output format (default: from the -o suffix, else py)",
    )
    parser.add_argument("-o", "--output", help="write here instead of standard output")
    parser.add_argument(
        "--package-path",
        action="append",
        default=[],
        metavar="DIR",
        help="extra folders to find source packages in (repeatable)",
    )
    parser.add_argument("-d", "--debug", action="store_true", help="tracebacks for errors")
    return parser


def _format_for(opts: argparse.Namespace) -> str:
    if opts.to:
        return str(opts.to)
    if opts.output:
        for fmt, suffix in FORMATS.items():
            short = suffix.removeprefix(".launch")
            if opts.output.endswith((suffix, short)) or (
                fmt == "yaml" and opts.output.endswith(".yml")
            ):
                return fmt
    return "py"


def command(args: Sequence[str]) -> int:
    """``mlaunch convert``'s work; errors go up to mlaunch.cli.main."""
    opts = build_parser().parse_args(list(args))
    path = os.path.abspath(opts.file)
    if not os.path.isfile(path):
        raise LaunchFileError(f"launch file {opts.file!r} does not exist")
    from mlaunch.ros.search import PackageSearch, searching

    output = None if opts.output in (None, "-") else opts.output
    with searching(PackageSearch(opts.package_path, path, os.environ)):
        result = convert(path, _format_for(opts), output)
    if output is None:
        sys.stdout.write(result)
        return 0
    try:
        with open(output, "w", encoding="utf-8") as f:
            f.write(result)
    except OSError as e:
        raise UsageError(f"cannot write {output!r}: {e.strerror}")
    return 0


__all__ = ["ConversionError", "command", "convert"]
