"""The smoke run's report: a table of expected vs seen, the output that explains it, JUnit XML."""

from __future__ import annotations

import os
from collections import deque

from mlaunch.smoke.expectations import Expectation

TYPE_CHECKING = False
if TYPE_CHECKING:
    from mlaunch.smoke import junit

STATUS_MARKS = {"met": "ok", "failed": "FAIL", "skipped": "--", "pending": "--"}


class Window:
    """What the run watched: ready ``ready_at`` s in (None: never), ``--hold`` ``hold`` s, the
    watch ended ``ended_at`` s in; a failure later than that is not seen, so the verdict says it."""

    __slots__ = ("ended_at", "hold", "ready_at")

    def __init__(self, ready_at: float | None, hold: float, ended_at: float) -> None:
        self.ready_at = ready_at
        self.hold = hold
        self.ended_at = ended_at

    @property
    def watched(self) -> float:
        """Seconds watched after ready (0 when never ready)."""
        return 0.0 if self.ready_at is None else max(0.0, self.ended_at - self.ready_at)

    def line(self, failed: bool) -> str:
        if self.ready_at is None:
            stop = "stopped at a failure" if failed else "stopped"
            return f"never ready: {stop} {self.ended_at:.1f} s in"
        held = f"--hold {self.hold:g}"
        if failed and self.watched < self.hold:
            return (
                f"ready after {self.ready_at:.1f} s; failed {self.watched:.1f} s into the"
                f" {self.hold:g} s hold"
            )
        return (
            f"ready after {self.ready_at:.1f} s, then watched {self.watched:.1f} s ({held}):"
            f" a failure after {self.ended_at:.1f} s is not seen"
        )

    def properties(self) -> dict[str, str]:
        """The JUnit suite's properties."""
        return {
            "ready_after": "" if self.ready_at is None else f"{self.ready_at:.3f}",
            "hold": f"{self.hold:g}",
            "watched_after_ready": f"{self.watched:.3f}",
        }


# --- the report -----------------------------------------------------------------------------------


class Report:
    """The summary table and the JUnit file, from the expectations after the run."""

    def __init__(
        self,
        path: str,
        expectations: list[Expectation],
        rings: dict[str, deque[str]],
        duration: float,
        window: Window | None = None,
        properties: dict[str, str] | None = None,
        notes: list[str] | None = None,
    ) -> None:
        self.path = path
        self.expectations = expectations
        self.rings = rings
        self.duration = duration
        self.window = window
        # More of the run for the JUnit suite's properties (its ROS domain ...), and in words
        # for the table.
        self.properties = dict(properties or {})
        self.notes = list(notes or [])

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
        if self.window is not None:
            out.append(f"  {self.window.line(bool(failed))}")
        out += [f"  {note}" for note in self.notes]
        rows = [
            (STATUS_MARKS.get(e.status, "?"), _at(e), e.describe(), e.seen)
            for e in self.expectations
        ]
        w_expect = min(60, max(len("expected"), *(len(r[2]) for r in rows)))
        out.append(f"  {'':4}  {'at':>6}  {'expected':<{w_expect}}  seen")
        for status, at, expected, seen in rows:
            if len(expected) > w_expect:
                # A long row (a long label) keeps the seen column: its seen goes on the next line.
                out.append(f"  {status:<4}  {at:>6}  {expected}")
                out.append(f"  {'':4}  {'':>6}  {'':<{w_expect}}  {seen}")
            else:
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

    def data(self) -> dict[str, object]:
        """The verdict as data (``mlaunch test --format json``, the artifacts' verdict.json)."""
        from mlaunch.smoke.expectations import expectation_data

        checks = []
        for e in self.expectations:
            item = expectation_data(e)
            item.update(status=e.status, seen=e.seen, at=e.at, labels=list(e.labels))
            checks.append(item)
        window = self.window
        return {
            "file": self.path,
            "passed": self.passed,
            "duration": round(self.duration, 3),
            "window": None
            if window is None
            else {
                "ready_after": window.ready_at,
                "hold": window.hold,
                "watched_after_ready": round(window.watched, 3),
            },
            **self.properties,
            "checks": checks,
            "output": {label: list(lines) for label, lines in self.rings.items()},
        }

    def json(self) -> str:
        import json

        return json.dumps(self.data(), indent=2) + "\n"

    def write_junit(self, path: str) -> None:
        from mlaunch.smoke import junit

        junit.write_suites(path, [self.suite()])

    def suite(self) -> junit.Suite:
        """The JUnit testsuite of this run: a testcase per expectation, the window's and the
        run's properties."""
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
        name = f"mlaunch test {os.path.basename(self.path)}"
        return junit.Suite(name, cases, self.duration, self.junit_properties())

    def junit_properties(self) -> dict[str, str]:
        window = self.window.properties() if self.window is not None else {}
        return {**window, **self.properties}


def _at(e: Expectation) -> str:
    return "" if e.at is None else f"{e.at:.1f}s"
