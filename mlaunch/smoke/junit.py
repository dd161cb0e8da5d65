"""JUnit XML for CI systems: one testsuite per launch, one testcase per expectation.

The dialect is the common subset GitLab, Jenkins, GitHub reporters and Buildkite read:
``<testsuites><testsuite name tests failures errors skipped time timestamp hostname>`` with
``<testcase classname name time>`` holding ``<failure message type>`` and ``<system-out>``.
"""

from __future__ import annotations

import os
import re
import socket
import time
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import dataclass

# XML 1.0 cannot carry these at all (not even escaped); ANSI colour codes are noise in a report.
_INVALID_XML = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\ufffe\uffff]")
_ANSI = re.compile(r"\x1b\[[0-9;?]*[A-Za-z]")


@dataclass
class Case:
    """One testcase: passed when ``failure`` is None, skipped when ``skipped`` is set."""

    name: str
    classname: str
    time: float = 0.0
    failure: str | None = None
    details: str = ""
    system_out: str = ""
    skipped: str | None = None


def xml_text(text: str) -> str:
    """Text that XML 1.0 can hold: no colour codes, no control characters."""
    return _INVALID_XML.sub("\ufffd", _ANSI.sub("", text))


def render(
    suite: str, cases: Sequence[Case], *, duration: float, started: float | None = None
) -> str:
    """The XML document for one suite."""
    failures = sum(1 for c in cases if c.failure is not None)
    skipped = sum(1 for c in cases if c.skipped is not None and c.failure is None)
    stamp = time.strftime("%Y-%m-%dT%H:%M:%S", time.localtime(started or time.time()))
    root = ET.Element("testsuites", tests=str(len(cases)), failures=str(failures))
    root.set("time", f"{duration:.3f}")
    node = ET.SubElement(
        root,
        "testsuite",
        name=xml_text(suite),
        tests=str(len(cases)),
        failures=str(failures),
        errors="0",
        skipped=str(skipped),
        time=f"{duration:.3f}",
        timestamp=stamp,
        hostname=socket.gethostname(),
    )
    for case in cases:
        element = ET.SubElement(
            node,
            "testcase",
            classname=xml_text(case.classname),
            name=xml_text(case.name),
            time=f"{case.time:.3f}",
        )
        if case.failure is not None:
            failure = ET.SubElement(
                element, "failure", message=xml_text(case.failure), type="mlaunch.test"
            )
            failure.text = xml_text(case.details or case.failure)
        elif case.skipped is not None:
            ET.SubElement(element, "skipped", message=xml_text(case.skipped))
        if case.system_out:
            ET.SubElement(element, "system-out").text = xml_text(case.system_out)
    ET.indent(root)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


def write(path: str, suite: str, cases: Sequence[Case], *, duration: float) -> None:
    """Write the report atomically (a CI step reading it never sees half a file)."""
    text = render(suite, cases, duration=duration)
    folder = os.path.dirname(os.path.abspath(path))
    os.makedirs(folder, exist_ok=True)
    tmp = f"{path}.{os.getpid()}.tmp"
    with open(tmp, "w", encoding="utf-8") as f:
        f.write(text)
    os.replace(tmp, path)
