"""``assertSequentialStdout``: texts found in a process's output in the order the test asks.

PYTEST_DONT_REWRITE: these raise their own AssertionErrors with their own messages.
"""

from __future__ import annotations

from mlaunch.launch_testing.util.proc_lookup import resolveProcesses

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

# How many pieces of output around the last match a failure shows (before, after), and how many
# lines it keeps on each side of where the last match ended.
_PIECES_BEFORE = 2
_PIECES_AFTER = 4
_CONTEXT_LINES = 3


class SequentialTextChecker:
    """Finds texts in the order asked, each after where the previous one was found.

    ``output`` is a list of pieces of output (one per ProcessIO event, several lines each); a
    text is looked for within one piece.
    """

    def __init__(self, output: list[str]) -> None:
        self._output = output
        self._piece = 0  # which piece of output the last match was in
        self._offset = 0  # and where in it the last match ended

    def assertInText(self, msg: str) -> None:
        self.assertInStdout(msg)

    def assertInStdout(self, msg: str) -> None:
        offset = self._offset
        for index in range(self._piece, len(self._output)):
            found = self._output[index].find(msg, offset)
            if found >= 0:
                self._piece, self._offset = index, found + len(msg)
                return
            offset = 0
        raise AssertionError(
            f"'{msg}' not found in sequence after previous match.  "
            f"The output near the last matched line:\n{self.get_nearby_lines()}"
        )

    def get_nearby_lines(self) -> str:
        """The lines around where the last match ended: up to three line breaks back and three
        forward, within the pieces just before and after it (launch_testing's window)."""
        first = max(0, self._piece - _PIECES_BEFORE)
        text = "".join(self._output[first : self._piece + _PIECES_AFTER])
        here = self._offset + sum(len(piece) for piece in self._output[first : self._piece])
        start = here
        for _ in range(_CONTEXT_LINES):
            start = max(text.rfind("\n", 0, start), 0)
        if start:
            start += 1  # it points at a line break: the window begins after it
        end = here
        for _ in range(_CONTEXT_LINES):
            end = max(text.find("\n", end + 1), end)
        return text[start:end]


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
    """A context whose checker finds texts of ``process``'s output in order.

    There is no reliable order between the output of two processes, so ``process`` must name
    exactly one. All of its output is checked, stderr included, as launch_testing does.
    """
    action = resolveProcesses(
        proc_output, process=process, cmd_args=cmd_args, strict_proc_matching=True
    )[0]
    output = [io.text.decode("utf-8", "replace") for io in proc_output[action]]
    return _SequentialContext(SequentialTextChecker(output))


__all__ = ["SequentialTextChecker", "assertSequentialStdout"]
