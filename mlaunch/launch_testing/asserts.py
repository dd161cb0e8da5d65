"""``launch_testing.asserts``: exit codes and output of the processes under test.

PYTEST_DONT_REWRITE: these raise their own AssertionErrors with their own messages.
"""

from __future__ import annotations

from mlaunch.launch_testing.text import build_text_match, remove_ansi_escape_sequences
from mlaunch.launch_testing.util import NO_CMD_ARGS, resolveProcesses

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable, Sequence
    from typing import Any

EXIT_OK = 0
EXIT_SIGINT = 130
EXIT_SIGQUIT = 131
EXIT_SIGKILL = 137
EXIT_SIGSEGV = 139
EXIT_FORCED = 1


def assertExitCodes(
    proc_info: Any,
    allowable_exit_codes: Sequence[int] = (EXIT_OK,),
    process: Any = None,
    cmd_args: Any = None,
    *,
    strict_proc_matching: bool = True,
) -> None:
    """Every matching process exited with one of ``allowable_exit_codes`` (0 by default)."""
    for code in allowable_exit_codes:
        assert isinstance(code, int), f"Provided exit code {code!r} is not an int"
    actions = resolveProcesses(
        proc_info, process=process, cmd_args=cmd_args, strict_proc_matching=strict_proc_matching
    )
    for action in actions:
        info = proc_info[action]
        assert info.returncode in allowable_exit_codes, (
            f"Proc {info.process_name} exited with code {info.returncode}"
        )


def _stream_text(proc_output: Any, action: Any, stream: str) -> str:
    if stream not in ("stdout", "stderr"):
        raise ValueError(f"stream is {stream!r}; valid: 'stdout', 'stderr'")
    fd = 1 if stream == "stdout" else 2
    return "".join(io.text.decode("utf-8", "replace") for io in proc_output[action] if io.fd == fd)


def assertInStream(
    proc_output: Any,
    expected_output: Any,
    process: Any,
    cmd_args: Any = None,
    *,
    output_filter: Any = None,
    strict_proc_matching: bool = True,
    strip_ansi_escape_sequences: bool = True,
    stream: str = "stderr",
) -> None:
    """``expected_output`` (str, regex, or a list in order) is in a stream of ``process``."""
    actions = resolveProcesses(
        proc_output, process=process, cmd_args=cmd_args, strict_proc_matching=strict_proc_matching
    )
    if output_filter is not None and not callable(output_filter):
        raise ValueError("output_filter is not callable")
    match = build_text_match(expected_output)
    for action in actions:
        text = _stream_text(proc_output, action, stream)
        if strip_ansi_escape_sequences:
            text = remove_ansi_escape_sequences(text)
        if output_filter is not None:
            text = output_filter(text)
        if match(text) is not None:
            return
    names = ", ".join(sorted(a.process_details["name"] for a in actions))
    raise AssertionError(
        f"Did not find '{expected_output}' in output for any of the matching processes: {names}"
    )


def _in_one_stream(stream: str) -> Callable[..., None]:
    """assertInStream with ``stream`` fixed (assertInStdout, assertInStderr)."""

    def check(
        proc_output: Any,
        expected_output: Any,
        process: Any,
        cmd_args: Any = None,
        **options: Any,
    ) -> None:
        assertInStream(proc_output, expected_output, process, cmd_args, stream=stream, **options)

    check.__name__ = check.__qualname__ = f"assertIn{stream.capitalize()}"
    check.__doc__ = f"assertInStream on the {stream} of ``process``."
    return check


assertInStdout = _in_one_stream("stdout")
assertInStderr = _in_one_stream("stderr")


def assertDefaultStream() -> str:
    """The stream assertInStream looks at unless told (stderr, as in ROS 2)."""
    return "stderr"


class SequentialTextChecker:
    """Finds texts in the order asked, each after where the previous one was found."""

    def __init__(self, output: list[str]) -> None:
        self._output = output
        self._chunk = 0  # which piece of output the last match was in
        self._offset = 0  # and where in it the last match ended

    def assertInText(self, msg: str) -> None:
        self.assertInStdout(msg)

    def assertInStdout(self, msg: str) -> None:
        offset = self._offset
        for index in range(self._chunk, len(self._output)):
            found = self._output[index].find(msg, offset)
            if found >= 0:
                self._chunk, self._offset = index, found + len(msg)
                return
            offset = 0
        raise AssertionError(
            f"'{msg}' not found in sequence after previous match.  "
            f"The output near the last matched line:\n{self.get_nearby_lines()}"
        )

    def get_nearby_lines(self) -> str:
        """A few lines around where the last match ended, with an arrow at it."""
        before = "".join(self._output[max(0, self._chunk - 2) : self._chunk])
        here = self._output[self._chunk] if self._chunk < len(self._output) else ""
        after = "".join(self._output[self._chunk + 1 : self._chunk + 4])
        head = (before + here[: self._offset]).splitlines()[-2:]
        tail = (here[self._offset :] + after).splitlines()[:2]
        return "\n".join([*head, " ^^^ last match ^^^", *tail])


class _SequentialContext:
    """``with assertSequentialStdout(...) as cm``: cm is a SequentialTextChecker."""

    def __init__(self, checker: SequentialTextChecker) -> None:
        self.checker = checker

    def __enter__(self) -> SequentialTextChecker:
        return self.checker

    def __exit__(self, *exc_info: object) -> None:
        return None


def assertSequentialStdout(
    proc_output: Any, process: Any, cmd_args: Any = None
) -> _SequentialContext:
    """A context whose checker finds stdout texts of ``process`` in order."""
    action = resolveProcesses(
        proc_output, process=process, cmd_args=cmd_args, strict_proc_matching=True
    )[0]
    # All of its output, stderr included, as ROS 2 checks it (the name says stdout).
    output = [io.text.decode("utf-8", "replace") for io in proc_output[action]]
    return _SequentialContext(SequentialTextChecker(output))


__all__ = [
    "EXIT_OK",
    "EXIT_SIGINT",
    "EXIT_SIGKILL",
    "EXIT_SIGQUIT",
    "EXIT_SIGSEGV",
    "NO_CMD_ARGS",
    "SequentialTextChecker",
    "assertDefaultStream",
    "assertExitCodes",
    "assertInStderr",
    "assertInStdout",
    "assertInStream",
    "assertSequentialStdout",
]
