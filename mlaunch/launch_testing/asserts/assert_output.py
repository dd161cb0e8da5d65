"""``assertInStream`` and its fixed-stream forms: a text in what a process printed.

PYTEST_DONT_REWRITE: these raise their own AssertionErrors with their own messages.
"""

from __future__ import annotations

from mlaunch.launch_testing.tools.text import build_text_match, remove_ansi_escape_sequences
from mlaunch.launch_testing.util.proc_lookup import resolveProcesses

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Callable
    from typing import Any


def _stream_text(proc_output: Any, action: Any, stream: str) -> str:
    if stream not in ("stdout", "stderr"):
        raise ValueError("Invalid value for stream; must be 'stdout' or 'stderr'")
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
        *,
        output_filter: Any = None,
        strict_proc_matching: bool = True,
        strip_ansi_escape_sequences: bool = True,
    ) -> None:
        assertInStream(
            proc_output,
            expected_output,
            process,
            cmd_args,
            output_filter=output_filter,
            strict_proc_matching=strict_proc_matching,
            strip_ansi_escape_sequences=strip_ansi_escape_sequences,
            stream=stream,
        )

    check.__name__ = check.__qualname__ = f"assertIn{stream.capitalize()}"
    check.__doc__ = f"assertInStream on the {stream} of ``process``."
    return check


assertInStdout = _in_one_stream("stdout")
assertInStderr = _in_one_stream("stderr")


def assertDefaultStream() -> str:
    """The stream assertInStream looks at unless told (stderr, as in ROS 2)."""
    return "stderr"


__all__ = ["assertDefaultStream", "assertInStderr", "assertInStdout", "assertInStream"]
