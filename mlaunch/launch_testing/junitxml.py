"""The JUnit XML report of a launch test, in launch_testing's structure.

``<testsuites name=PKG.FILE tests failures errors time>``, one ``<testsuite>`` per run (its name
is the run's, with parameters), one ``<testcase classname name time>`` per test with its
``<failure>``, ``<error>`` or ``<skipped>`` (the formatted traceback in ``message``).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Mapping
    from typing import Any


def _seconds(value: float) -> str:
    return str(round(value, 3))


def results_to_xml(name: str, results: Mapping[Any, Any]) -> ET.ElementTree:
    root = ET.Element("testsuites", name=name)
    totals = {"tests": 0, "failures": 0, "errors": 0}
    elapsed = 0.0
    for run, result in results.items():
        totals["tests"] += result.testsRun
        totals["failures"] += len(result.failures)
        totals["errors"] += len(result.errors)
        elapsed += sum(result.testTimes.values())
        root.append(_suite(str(run), result))
    for key, value in totals.items():
        root.set(key, str(value))
    root.set("time", _seconds(elapsed))
    return ET.ElementTree(root)


def _suite(name: str, result: Any) -> ET.Element:
    suite = ET.Element(
        "testsuite",
        name=name,
        tests=str(result.testsRun),
        failures=str(len(result.failures)),
        errors=str(len(result.errors)),
        skipped=str(len(result.skipped)),
        time=_seconds(sum(result.testTimes.values())),
    )
    times = result.testTimes
    for case in result.testCases:
        suite.append(_case(case, times.get(case, 0.0), result))
    return suite


def _case(case: Any, seconds: float, result: Any) -> ET.Element:
    method_id, _, qualifiers = case.id().partition(" ")
    classname, _, method = method_id.rpartition(".")
    element = ET.Element(
        "testcase",
        classname=classname,
        name=f"{method} {qualifiers}".strip(),
        time=_seconds(seconds),
    )
    for tag, outcomes in (
        ("failure", result.failures),
        ("error", result.errors),
        ("skipped", result.skipped),
    ):
        for outcome_case, text in outcomes:
            if outcome_case == case:
                element.append(ET.Element(tag, message=text))
    return element


def write_report(path: str, name: str, results: Mapping[Any, Any]) -> None:
    results_to_xml(name, results).write(path, encoding="utf-8", xml_declaration=True)
