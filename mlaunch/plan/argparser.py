"""The command-line parser of mlaunch's commands: a bad option is one line that says the fix.

argparse prints the whole usage (9 lines for ``mlaunch``) before the one line that matters, calls
an abbreviation of two spellings of one option "ambiguous", and offers no did-you-mean. This
parser says the error, what was probably meant and where the options are listed, in one line,
and takes an abbreviation that only spellings of one option share as that option.
"""

from __future__ import annotations

import argparse
import re

from mlaunch.plan.errors import closest

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any, NoReturn

# Compiled on the first error only: nothing is compiled on a run's way to its first child.
_UNRECOGNIZED = r"unrecognized arguments: (\S+)"


class ArgumentParser(argparse.ArgumentParser):
    """argparse's parser with one-line errors (exit status 2, as argparse's)."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: error: {message}{self._hint(message)}\n")

    def _hint(self, message: str) -> str:
        unknown = re.match(_UNRECOGNIZED, message)
        hint = ""
        if unknown and unknown.group(1).startswith("-"):
            # Compared without the dashes, which every option shares (--bogus is not --ros2).
            options = {o.lstrip("-"): o for o in self._option_string_actions}
            close = closest(unknown.group(1).split("=", 1)[0].lstrip("-"), options)
            hint = f" (did you mean {options[close]!r}?)" if close else ""
        return f"{hint}; '{self.prog} --help' lists the options"

    def _get_option_tuples(self, option_string: str) -> list[Any]:
        # One match per option: --show-arg abbreviates --show-args and --show-arguments, which
        # are the same option, so it is not ambiguous.
        seen: set[int] = set()
        tuples = []
        for option in super()._get_option_tuples(option_string):
            if id(option[0]) not in seen:
                seen.add(id(option[0]))
                tuples.append(option)
        return tuples
