"""``mlaunch test FILE... -j N``: several launch files tested at once, one report, one JUnit file.

Each file is an ordinary ``mlaunch test FILE`` run in a process of its own (so each claims a
ROS domain of its own: mlaunch.ros.domain), with the same arguments and test options; at most N
run at a time. Their output goes to a file each in the run's log folder; a line says each
verdict as it comes; at the end the tables of the runs that failed, and a summary table. The
JUnit report (``--junit FILE``) holds every run's testsuite; a run that ended without writing
one (a launch file that does not load) is a testsuite whose one testcase failed with its last
output.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import dataclass, field

from mlaunch.plan.errors import EXIT_FAILURE, EXIT_OK, UsageError, exit_for_signal

# How much of a run's output the report and a stand-in testsuite show.
TAIL_LINES = 30


@dataclass
class Job:
    """One launch file's run."""

    index: int
    path: str
    output: str  # where its stdout and stderr go
    junit: str  # where its JUnit report goes
    extra: list[str] = field(default_factory=list)  # this run's own options (its --artifacts)
    code: int | None = None
    duration: float = 0.0
    process: subprocess.Popen[bytes] | None = field(default=None, repr=False)

    @property
    def name(self) -> str:
        return os.path.basename(self.path)

    def text(self) -> str:
        try:
            with open(self.output, encoding="utf-8", errors="replace") as f:
                return f.read()
        except OSError:
            return ""

    def table(self) -> str:
        """Its verdict table (from the report's first line on), or its last lines."""
        text = self.text()
        at = text.rfind("\nmlaunch test ")
        if at >= 0:
            return text[at + 1 :]
        return "\n".join(text.splitlines()[-TAIL_LINES:]) + "\n"

    def domain(self) -> str:
        suite = self.suite()
        if suite is None:
            return ""
        for prop in suite.iter("property"):
            if prop.get("name") == "ros_domain_id":
                return prop.get("value", "")
        return ""

    def suite(self) -> ET.Element | None:
        try:
            return ET.parse(self.junit).getroot().find("testsuite")
        except (OSError, ET.ParseError):
            return None


def parse_jobs(value: str) -> int:
    try:
        jobs = int(value)
    except ValueError:
        jobs = 0
    if jobs < 1:
        raise UsageError(f"-j {value!r}: expected a number of launches to run at once (>= 1)")
    return jobs


def run_many(
    files: Sequence[str],
    shared: Sequence[str],
    jobs: int,
    junit_path: str | None,
    repeat: int = 1,
    evidence: str | None = None,
) -> int:
    """Test ``files`` with ``shared`` arguments and options, ``jobs`` at a time, each
    ``repeat`` times (then a table says how often each check held)."""
    files = [path for path in files for _ in range(repeat)]
    from mlaunch.engine.logfiles import make_run_log_dir

    for path in files:
        if not os.path.isfile(path):
            raise UsageError(f"launch file {path!r} does not exist (mlaunch test FILE... -j N)")
    if junit_path:
        from mlaunch.smoke import junit

        junit.check_target(junit_path)
    if os.environ.get("ROS_DOMAIN_ID", "").strip():
        print(
            f"mlaunch test: ROS_DOMAIN_ID={os.environ['ROS_DOMAIN_ID']} is set, so the"
            f" {len(files)} launches share that domain (unset it to give each its own)",
            flush=True,
        )
    folder = make_run_log_dir(os.environ)
    width = len(str(len(files)))
    batch = [
        Job(
            i,
            path,
            os.path.join(folder, f"{i:0{width}}-{os.path.basename(path)}.out"),
            os.path.join(folder, f"{i:0{width}}-{os.path.basename(path)}.junit.xml"),
        )
        for i, path in enumerate(files, 1)
    ]
    for job in batch:  # each run's evidence in a folder of its own
        if evidence:
            name = f"{job.index:0{width}}-{os.path.basename(job.path)}"
            job.extra = ["--artifacts", os.path.join(evidence, name)]
    started = time.monotonic()
    stopped = _Runner(batch, shared, jobs).run()
    elapsed = time.monotonic() - started
    sys.stdout.write(summary(batch, elapsed, folder))
    if repeat > 1:
        sys.stdout.write(flakiness(batch))
    sys.stdout.flush()
    if junit_path:
        write_junit(junit_path, batch)
    if stopped:
        return exit_for_signal(stopped)
    return EXIT_OK if all(j.code == 0 for j in batch) else EXIT_FAILURE


class _Runner:
    """Starts the jobs, at most ``jobs`` at a time; a stop signal is passed to every child."""

    def __init__(self, batch: list[Job], shared: Sequence[str], jobs: int) -> None:
        self.batch = batch
        self.shared = list(shared)
        self.slots = threading.Semaphore(jobs)
        self.lock = threading.Lock()
        self.done = 0
        self.stopped = 0  # the signal that stopped the batch, 0: none

    def run(self) -> int:
        previous = {
            sig: signal.signal(sig, self._on_signal)
            for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)
        }
        try:
            threads = [threading.Thread(target=self._one, args=(job,)) for job in self.batch]
            for thread in threads:
                thread.start()
            for thread in threads:
                while thread.is_alive():
                    thread.join(0.2)  # the main thread stays able to take signals
        finally:
            for sig, handler in previous.items():
                signal.signal(sig, handler)
        return self.stopped

    def _on_signal(self, signum: int, frame: object) -> None:
        with self.lock:
            self.stopped = self.stopped or signum
            running = [j.process for j in self.batch if j.process is not None]
        for process in running:
            if process.poll() is None:
                process.send_signal(signum)

    def _one(self, job: Job) -> None:
        with self.slots:
            with self.lock:
                if self.stopped:
                    return
                argv = [sys.executable, "-m", "mlaunch", "test", job.path, *self.shared]
                argv += ["--junit", job.junit, *job.extra]
                start = time.monotonic()
                with open(job.output, "wb") as out:
                    job.process = subprocess.Popen(
                        argv, stdout=out, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL
                    )
            job.code = job.process.wait()
            job.duration = time.monotonic() - start
        with self.lock:
            self.done += 1
            line = progress(job, self.done, len(self.batch))
        sys.stdout.write(line)
        sys.stdout.flush()


def verdict(job: Job) -> str:
    if job.code is None:
        return "NOT RUN"
    if job.code == 0:
        return "PASSED"
    if job.code == 1:
        return "FAILED"
    if job.code >= 128:
        return f"STOPPED ({signal_words(job.code)})"
    return f"ERROR (exit status {job.code})"


def signal_words(code: int) -> str:
    try:
        return signal.Signals(code - 128).name
    except ValueError:
        return f"status {code}"


def progress(job: Job, done: int, total: int) -> str:
    domain = job.domain()
    where = f" (ROS domain {domain})" if domain else ""
    head = f"mlaunch test: [{done}/{total}] {verdict(job)} in {job.duration:.1f} s"
    return f"{head}: {job.path}{where}\n"


def summary(batch: list[Job], elapsed: float, folder: str) -> str:
    """The failed runs' tables, then one line per run."""
    out = []
    for job in batch:
        if job.code not in (0, None):
            out.append(f"\n===== {job.path}: {verdict(job)}\n{job.table()}")
    passed = sum(1 for j in batch if j.code == 0)
    out.append(
        f"\nmlaunch test: {passed} of {len(batch)} passed in {elapsed:.1f} s"
        f" (each run's output: {folder})\n"
    )
    for job in batch:
        mark = "ok" if job.code == 0 else "FAIL" if job.code is not None else "--"
        domain = job.domain()
        out.append(
            f"  {mark:<4}  {job.duration:6.1f}s  {job.path}"
            + (f"  (ROS domain {domain})" if domain else "")
            + "\n"
        )
    return "".join(out)


def flakiness(batch: list[Job]) -> str:
    """Per file and check: in how many runs it held; a check that held in some runs and not
    in others is flaky."""
    out = []
    for path in dict.fromkeys(j.path for j in batch):
        jobs = [j for j in batch if j.path == path]
        held: dict[str, int] = {}
        for job in jobs:
            suite = job.suite()
            cases = [] if suite is None else suite.findall("testcase")
            if suite is None:
                cases = []
                held.setdefault("the launch file runs", 0)
            for case in cases:
                name = case.get("name", "")
                passed = case.find("failure") is None and case.find("skipped") is None
                held[name] = held.get(name, 0) + int(passed)
        runs = len(jobs)
        out.append(f"\nflakiness over {runs} runs: {path}\n")
        for name, count in held.items():
            mark = "ok" if count == runs else "FAIL" if count == 0 else "FLAKY"
            out.append(f"  {mark:<5}  {count:>3}/{runs}  {name}\n")
    return "".join(out)


def write_junit(path: str, batch: list[Job]) -> None:
    """One report with every run's testsuite."""
    from mlaunch.smoke import junit

    root = ET.Element("testsuites")
    tests = failures = 0
    for job in batch:
        suite = job.suite()
        if suite is None:
            suite = _stand_in_suite(job)
        tests += int(suite.get("tests", "0"))
        failures += int(suite.get("failures", "0"))
        root.append(suite)
    root.set("tests", str(tests))
    root.set("failures", str(failures))
    root.set("time", f"{max((j.duration for j in batch), default=0.0):.3f}")
    ET.indent(root)
    data = ET.tostring(root, encoding="unicode")
    junit.write_report(path, ('<?xml version="1.0" encoding="UTF-8"?>\n' + data + "\n").encode())


def _stand_in_suite(job: Job) -> ET.Element:
    """A testsuite for a run that wrote none: one testcase, failed with its last output."""
    from mlaunch.smoke import junit

    tail = "\n".join(job.text().splitlines()[-TAIL_LINES:])
    case = junit.Case(
        name="the launch file runs",
        classname=f"mlaunch.test.{job.name.split('.')[0] or 'launch'}",
        time=job.duration,
        failure=f"mlaunch test {verdict(job)}",
        details=tail,
        system_out=tail,
    )
    document = junit.render(f"mlaunch test {job.name}", [case], duration=job.duration)
    suite = ET.fromstring(document.split("\n", 1)[1]).find("testsuite")
    assert suite is not None
    return suite
