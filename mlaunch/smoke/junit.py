"""JUnit XML for CI systems: one testsuite per launch, one testcase per expectation.

The dialect is the common subset GitLab, Jenkins, GitHub reporters and Buildkite read:
``<testsuites><testsuite name tests failures errors skipped time timestamp hostname>`` with
``<testcase classname name time>`` holding ``<failure message type>`` and ``<system-out>``.
"""

from __future__ import annotations

import contextlib
import errno
import os
import re
import socket
import stat
import time
import xml.etree.ElementTree as ET
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

from mlaunch.plan.errors import OutputError, UsageError

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


@dataclass
class Suite:
    """One launch's testsuite: its cases and ``properties`` (the watched window, the domain)."""

    name: str
    cases: Sequence[Case]
    duration: float
    properties: Mapping[str, str] = field(default_factory=dict)
    started: float | None = None


def render(
    suite: str,
    cases: Sequence[Case],
    *,
    duration: float,
    started: float | None = None,
    properties: Mapping[str, str] | None = None,
) -> str:
    """The XML document for one suite."""
    return render_suites([Suite(suite, cases, duration, properties or {}, started)])


def render_suites(suites: Sequence[Suite]) -> str:
    """The XML document for several suites (``mlaunch test -j``: one per launch file)."""
    tests = sum(len(s.cases) for s in suites)
    failures = sum(_failures(s.cases) for s in suites)
    root = ET.Element("testsuites", tests=str(tests), failures=str(failures))
    root.set("time", f"{max((s.duration for s in suites), default=0.0):.3f}")
    for suite in suites:
        _suite(root, suite)
    ET.indent(root)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


def _failures(cases: Sequence[Case]) -> int:
    return sum(1 for c in cases if c.failure is not None)


def _suite(root: ET.Element, suite: Suite) -> None:
    cases = suite.cases
    skipped = sum(1 for c in cases if c.skipped is not None and c.failure is None)
    stamp = time.strftime("%Y-%m-%dT%H:%M:%S", time.localtime(suite.started or time.time()))
    node = ET.SubElement(
        root,
        "testsuite",
        name=xml_text(suite.name),
        tests=str(len(cases)),
        failures=str(_failures(cases)),
        errors="0",
        skipped=str(skipped),
        time=f"{suite.duration:.3f}",
        timestamp=stamp,
        hostname=socket.gethostname(),
    )
    if suite.properties:
        properties = ET.SubElement(node, "properties")
        for name, value in suite.properties.items():
            ET.SubElement(properties, "property", name=xml_text(name), value=xml_text(value))
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


def write(
    path: str,
    suite: str,
    cases: Sequence[Case],
    *,
    duration: float,
    properties: Mapping[str, str] | None = None,
) -> None:
    """Write the report to ``path`` (raises OutputError when it cannot: exit status 74)."""
    write_suites(path, [Suite(suite, cases, duration, properties or {})])


def write_suites(path: str, suites: Sequence[Suite]) -> None:
    """Write several suites as one report (raises OutputError when it cannot: exit status 74)."""
    try:
        write_report(path, render_suites(suites).encode("utf-8"))
    except OSError as e:
        raise OutputError(f"cannot write the JUnit report {path}: {e.strerror or e}") from None


def write_report(path: str, data: bytes) -> None:
    """Write ``data`` into what ``path`` is: a regular file (or a new one) atomically, so a CI
    step reading it never sees half a file; a device or a FIFO (``/dev/null``, ``/dev/stdout``,
    a pipe) by writing into it, never by renaming a file over it."""
    try:
        st = os.stat(path)
    except FileNotFoundError:
        st = None
    if st is not None and not stat.S_ISREG(st.st_mode):
        _write_into(path, data, st)
        return
    real = os.path.realpath(path)  # a symlink to the report: the report is replaced, not it
    folder, name = os.path.split(real)
    os.makedirs(folder, exist_ok=True)
    # O_EXCL: never a planted name followed. A new report gets open()'s mode, a replaced one keeps.
    tmp = os.path.join(folder, f".{name}.{os.getpid()}.{os.urandom(4).hex()}.tmp")
    fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW | os.O_CLOEXEC, 0o666)
    try:
        if st is not None:
            os.fchmod(fd, stat.S_IMODE(st.st_mode))
        with open(fd, "wb") as f:
            f.write(data)
        os.replace(tmp, real)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


def check_target(path: str) -> None:
    """Raise UsageError now, before the run, if the report could not be written at ``path``."""
    try:
        _check(path)
    except OSError as e:
        raise UsageError(
            f"--junit {path}: the report could not be written there: {e.strerror or e}"
        ) from None


def _check(path: str) -> None:
    try:
        st = os.stat(path)
    except FileNotFoundError:
        st = None
    if st is not None and stat.S_ISDIR(st.st_mode):
        raise UsageError(f"--junit {path}: that is a folder; name a file in it")
    if st is not None and stat.S_ISSOCK(st.st_mode):
        raise UsageError(f"--junit {path}: that is a socket; name a file, a FIFO or a device")
    if st is not None and not stat.S_ISREG(st.st_mode):
        if not os.access(path, os.W_OK):
            raise PermissionError(errno.EACCES, os.strerror(errno.EACCES))
        return
    folder = os.path.dirname(os.path.realpath(path))
    os.makedirs(folder, exist_ok=True)
    probe = os.path.join(folder, f".junit-probe.{os.getpid()}.{os.urandom(4).hex()}")
    os.close(os.open(probe, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW, 0o600))
    os.unlink(probe)


# A FIFO's reader may open it a moment after mlaunch (a CI step reading it): waited for this long.
FIFO_READER_WAIT = 10.0


def _write_into(path: str, data: bytes, st: os.stat_result) -> None:
    """Write into a device or a FIFO as it is (O_NONBLOCK at open: a FIFO nobody reads yet is
    waited on for FIFO_READER_WAIT, not forever)."""
    deadline = time.monotonic() + FIFO_READER_WAIT
    while True:
        try:
            fd = os.open(path, os.O_WRONLY | os.O_NONBLOCK | os.O_NOCTTY | os.O_CLOEXEC)
            break
        except OSError as e:
            if e.errno != errno.ENXIO or not stat.S_ISFIFO(st.st_mode):
                raise
            if time.monotonic() > deadline:
                raise OSError(errno.ENXIO, "nobody opened the FIFO to read it") from None
            time.sleep(0.05)
    try:
        os.set_blocking(fd, True)
        view = memoryview(data)
        while view:
            view = view[os.write(fd, view) :]
    finally:
        os.close(fd)
