"""The smoke run's report: a table of expected vs seen, the output that explains it, JUnit XML."""

from __future__ import annotations

import os
from collections import deque

from mlaunch.smoke.expectations import Expectation

STATUS_MARKS = {"met": "ok", "failed": "FAIL", "skipped": "--", "pending": "--"}

# --- the report -----------------------------------------------------------------------------------


class Report:
    """The summary table and the JUnit file, from the expectations after the run."""

    def __init__(
        self,
        path: str,
        expectations: list[Expectation],
        rings: dict[str, deque[str]],
        duration: float,
    ) -> None:
        self.path = path
        self.expectations = expectations
        self.rings = rings
        self.duration = duration

    @property
    def failures(self) -> list[Expectation]:
        return [e for e in self.expectations if e.status == "failed"]

    @property
    def passed(self) -> bool:
        return all(e.status == "met" for e in self.expectations)

    def table(self) -> str:
        failed = self.failures
        verdict = "PASSED" if not failed else f"FAILED ({len(failed)} of {len(self.expectations)})"
        out = [
            "",
            f"mlaunch test {verdict} in {self.duration:.1f} s: {self.path}",
        ]
        rows = [
            (STATUS_MARKS.get(e.status, "?"), _at(e), e.describe(), e.seen)
            for e in self.expectations
        ]
        w_expect = min(60, max(len("expected"), *(len(r[2]) for r in rows)))
        out.append(f"  {'':4}  {'at':>6}  {'expected':<{w_expect}}  seen")
        for status, at, expected, seen in rows:
            out.append(f"  {status:<4}  {at:>6}  {expected:<{w_expect}}  {seen}")
        for label in self._labels(failed):
            out.append("")
            out.append(f"last output of {label}:")
            lines = list(self.rings.get(label, ())) or ["(no output)"]
            out.extend(f"  | {line}" for line in lines)
        return "\n".join(out) + "\n"

    def _labels(self, failed: list[Expectation]) -> list[str]:
        labels: list[str] = []
        for e in failed:
            for label in e.labels or list(self.rings):
                if label not in labels:
                    labels.append(label)
        return labels

    def excerpt(self, e: Expectation) -> str:
        parts = []
        for label in e.labels or list(self.rings):
            lines = list(self.rings.get(label, ()))
            if not e.labels:
                lines = lines[-5:]
            parts.append(f"--- last output of {label} ---\n" + "\n".join(lines or ["(no output)"]))
        return "\n".join(parts)

    def write_junit(self, path: str) -> None:
        from mlaunch.smoke import junit

        stem = os.path.basename(self.path).split(".")[0] or "launch"
        cases = []
        for e in self.expectations:
            failure = e.seen if e.status == "failed" else None
            cases.append(
                junit.Case(
                    name=e.describe(),
                    classname=f"mlaunch.test.{stem}",
                    time=e.at or 0.0,
                    failure=failure,
                    skipped=e.seen if e.status in ("skipped", "pending") else None,
                    details=f"expected: {e.describe()}\nseen: {e.seen}\nfrom: {e.origin}",
                    system_out=self.excerpt(e) if failure else "",
                )
            )
        junit.write(
            path, f"mlaunch test {os.path.basename(self.path)}", cases, duration=self.duration
        )


def _at(e: Expectation) -> str:
    return "" if e.at is None else f"{e.at:.1f}s"
