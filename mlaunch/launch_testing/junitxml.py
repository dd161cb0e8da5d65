"""The JUnit XML report of a launch test, in launch_testing's structure.

``<testsuites name tests failures errors time>``, one ``<testsuite>`` per run (named after the
run, with its parameters), one ``<testcase classname name time>`` per test with its
``<failure>``, ``<error>`` or ``<skipped>`` (the formatted traceback or reason in ``message``).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Mapping
    from typing import Any


def _seconds(value: float) -> str:
    return str(round(value, 3))


def unittestResultsToXml(
    *, name: str = "launch_test", test_results: Mapping[Any, Any] | None = None
) -> ET.ElementTree:
    """The report of several results (``{run or name: result}``) as one ``<testsuites>``."""
    results = dict(test_results or {})
    root = ET.Element("testsuites", name=name)
    root.set("tests", str(sum(r.testsRun for r in results.values())))
    root.set("failures", str(sum(len(r.failures) for r in results.values())))
    root.set("errors", str(sum(len(r.errors) for r in results.values())))
    root.set("time", _seconds(sum(sum(r.testTimes.values()) for r in results.values())))
    for run, result in results.items():
        root.append(unittestResultToXml(str(run), result))
    return ET.ElementTree(root)


def unittestResultToXml(name: str, test_result: Any) -> ET.Element:
    """One result as a ``<testsuite>`` (it needs launch_testing's TestResult: the times)."""
    suite = ET.Element(
        "testsuite",
        name=name,
        tests=str(test_result.testsRun),
        failures=str(len(test_result.failures)),
        errors=str(len(test_result.errors)),
        skipped=str(len(test_result.skipped)),
        time=_seconds(sum(test_result.testTimes.values())),
    )
    for case in test_result.testCases:
        suite.append(unittestCaseToXml(test_result, case))
    return suite


def unittestCaseToXml(test_result: Any, test_case: Any) -> ET.Element:
    """One test as a ``<testcase>``: ``classname`` is the test id up to its method, ``name``
    the method and what follows it in the id (a parametrized run's values)."""
    method_id, _, qualifiers = test_case.id().partition(" ")
    classname, _, method = method_id.rpartition(".")
    element = ET.Element(
        "testcase",
        classname=classname,
        name=f"{method} {qualifiers}".strip(),
        time=_seconds(test_result.testTimes[test_case]),
    )
    for tag, outcomes in (
        ("failure", test_result.failures),
        ("error", test_result.errors),
        ("skipped", test_result.skipped),
    ):
        for outcome_case, text in outcomes:
            if outcome_case == test_case:
                element.append(ET.Element(tag, message=text))
    return element


__all__ = ["unittestCaseToXml", "unittestResultToXml", "unittestResultsToXml"]
