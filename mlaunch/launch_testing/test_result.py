"""The results of one TestRun: TestResult (tests that ran, with their times), FailResult (the
launch died before the active tests finished), SkipResult (a skipped test description)."""

from __future__ import annotations

import time
import unittest

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any


class _WholeRunResult(unittest.TestResult):
    """Every test of a run given the same outcome without running."""

    def __init__(self) -> None:
        super().__init__()
        self._cases: list[Any] = []

    def _give(self, test_run: Any, outcome: Any) -> None:
        for case in test_run.all_cases():
            outcome(case)
            self._cases.append(case)
            self.testsRun += 1

    @property
    def testCases(self) -> list[Any]:
        return list(self._cases)

    @property
    def testTimes(self) -> dict[Any, float]:
        return dict.fromkeys(self._cases, 0.0)


class FailResult(_WholeRunResult):
    """Every test of a run failed with ``message``: the processes under test died first."""

    def __init__(self, test_run: Any, message: str) -> None:
        super().__init__()
        error = (Exception, Exception(message), None)
        self._give(test_run, lambda case: self.addFailure(case, error))  # type: ignore[arg-type]

    def wasSuccessful(self) -> bool:
        return False


class SkipResult(_WholeRunResult):
    """Every test of a run skipped: its generate_test_description was decorated with a skip."""

    def __init__(self, test_run: Any, skip_reason: str = "") -> None:
        super().__init__()
        self._give(test_run, lambda case: self.addSkip(case, skip_reason))

    def wasSuccessful(self) -> bool:
        return True


class TestResult(unittest.TextTestResult):
    """A TextTestResult that remembers every test it ran and how long each took."""

    def __init__(self, stream: Any = None, descriptions: Any = None, verbosity: Any = None):
        super().__init__(stream, descriptions, verbosity)
        self._times: dict[unittest.TestCase, list[float]] = {}

    @property
    def testCases(self) -> list[unittest.TestCase]:
        return list(self._times)

    @property
    def testTimes(self) -> dict[unittest.TestCase, float]:
        return {case: end - start for case, (start, end) in self._times.items()}

    def startTest(self, test: unittest.TestCase) -> None:
        self._times[test] = [time.time(), 0.0]
        super().startTest(test)

    def stopTest(self, test: unittest.TestCase) -> None:
        self._times[test][1] = time.time()
        super().stopTest(test)

    def append(self, results: TestResult) -> None:
        """Add the results of the post-shutdown tests to the active tests' results."""
        self._times.update(results._times)
        self.failures += results.failures
        self.errors += results.errors
        self.testsRun += results.testsRun
        self.skipped += results.skipped
        self.expectedFailures += results.expectedFailures
        self.unexpectedSuccesses += results.unexpectedSuccesses


__all__ = ["FailResult", "SkipResult", "TestResult"]
