"""One small error hierarchy and the one table of exit statuses.

Every error knows where it happened; only a program's ``main`` (mlaunch.cli's, and the
``launch_test`` program's) catches errors, prints them once through ``report`` and returns the
status this table gives.
"""

from __future__ import annotations

import sys

TYPE_CHECKING = False  # mypy reads this as typing.TYPE_CHECKING; typing costs ~3 ms
if TYPE_CHECKING:
    from collections.abc import Iterable

# --- exit statuses ---------------------------------------------------------------------------

EXIT_OK = 0  # every process ended and nothing required failed; a smoke run or test passed
EXIT_FAILURE = 1  # a required process failed; a smoke expectation or a launch test failed
EXIT_USAGE = 2  # bad input: command line, launch file, argument, substitution, package
EXIT_INTERNAL = 70  # a bug in mlaunch (BSD's EX_SOFTWARE): reported with --debug for details
EXIT_OUTPUT = 74  # stdout cannot be written (BSD's EX_IOERR): a full disk, /dev/full, EIO
SIGNAL_BASE = 128  # stopped by signal N: 128 + N, as a shell reports it
EXIT_INTERRUPTED = SIGNAL_BASE + 2  # Ctrl-C (SIGINT)


def exit_for_signal(signum: int) -> int:
    """The status of a run stopped by signal ``signum`` (130 SIGINT, 143 SIGTERM, 129 SIGHUP)."""
    return SIGNAL_BASE + signum


def exit_status(error: BaseException) -> int:
    """The status a program exits with when ``error`` ends it."""
    if isinstance(error, MlaunchError):
        return error.exit_code
    if isinstance(error, KeyboardInterrupt):  # Ctrl-C; SIGTERM/SIGHUP carry their own status
        status = getattr(error, "exit_code", EXIT_INTERRUPTED)
        return status if isinstance(status, int) else EXIT_INTERRUPTED
    return EXIT_INTERNAL


def report(error: BaseException, *, debug: bool, prog: str = "mlaunch") -> int:
    """Print ``error`` once on stderr (a traceback too with ``debug``); return its exit status.

    An MlaunchError is the user's one line; anything else is mlaunch's bug, said as such.
    """
    if debug:
        import traceback

        traceback.print_exception(error)
    status = exit_status(error)
    if isinstance(error, MlaunchError):
        _say(f"{prog}: error: {error}")
    elif status == EXIT_INTERNAL:
        hint = "" if debug else " (run with --debug for the traceback)"
        _say(f"{prog}: internal error: {type(error).__name__}: {error}{hint}")
    return status


def _say(line: str) -> None:
    """One line on stderr, whatever became of it (closed, a broken pipe)."""
    try:
        sys.stderr.write(line + "\n")
        sys.stderr.flush()
    except (OSError, ValueError, AttributeError):
        pass


def is_own_module(name: str | None) -> bool:
    """Whether an ImportError's module is one of mlaunch's (then it is a bug, never user input)."""
    return bool(name) and (name == "mlaunch" or str(name).startswith("mlaunch."))


# --- the hierarchy -----------------------------------------------------------------------------


# Names a "did you mean" compares against at most (each comparison is microseconds).
CLOSE_NAMES_LIMIT = 20_000


def closest(name: str, names: Iterable[str]) -> str | None:
    """The one of ``names`` closest to ``name``, if any is close (difflib's measure)."""
    import difflib  # only on an error: it costs start-up time otherwise
    import itertools

    candidates = [n for n in itertools.islice(names, CLOSE_NAMES_LIMIT) if n != name]
    close = difflib.get_close_matches(name, candidates, n=1)
    return close[0] if close else None


def did_you_mean(name: str, names: Iterable[str]) -> str:
    """`` (did you mean 'x'?)`` when one of ``names`` is close to ``name``, else empty."""
    close = closest(name, names)
    return f" (did you mean {close!r}?)" if close else ""


class MlaunchError(Exception):
    """Base of every error mlaunch reports to the user as one line (no traceback without --debug).

    ``where`` is ``file:line`` (or ``file:line:col``) of the launch-file text at fault, ``what``
    names the action, tag or attribute involved. Both are filled in as the error travels up when
    they are not known where it is raised.
    """

    exit_code = EXIT_USAGE
    # The launch argument a bad value came from, when it came straight from one: the resolver
    # then names the argument's declaration too, where the user's command line can be fixed.
    argument: str | None = None

    def __init__(self, message: str, *, where: str | None = None, what: str | None = None):
        super().__init__(message)
        self.message = message
        self.where = where
        self.what = what

    def __str__(self) -> str:
        parts = []
        if self.where:
            parts.append(f"{self.where}:")
        if self.what:
            parts.append(f"{self.what}:")
        parts.append(self.message)
        return " ".join(parts)


class LaunchFileError(MlaunchError):
    """The launch file cannot be found, read or parsed (syntax, schema, unknown tags)."""


class LaunchFileTypeError(LaunchFileError, TypeError):
    """A launch file gave an argument of the wrong type (a TypeError too, as launch raises)."""


class SubstitutionFailure(MlaunchError):
    """A substitution cannot be performed (unset configuration, failing command, ...)."""


class SubstitutionTypeError(SubstitutionFailure, TypeError):
    """A performed parameter value is of no type a parameter may have (a TypeError too, as
    launch_ros raises)."""


class SubstitutionValueError(SubstitutionFailure, ValueError):
    """A performed value cannot be read as the type it must have (a ValueError too, as launch's
    type coercion raises)."""


class InvalidConditionExpressionError(SubstitutionFailure, ValueError):
    """An if/unless expression is not one of true, false, 1, 0 (a ValueError, as launch's)."""


class LaunchArgumentError(MlaunchError, RuntimeError):
    """A launch argument is missing, malformed or outside its choices (a RuntimeError too, as
    launch raises)."""


class PackageNotFoundError(MlaunchError):
    """A ROS package or an executable inside one cannot be found."""


class UsageError(MlaunchError):
    """The command line itself is wrong."""


class OutputError(MlaunchError):
    """Standard output cannot be written (not a reader that left: that is SIGPIPE's 141)."""

    exit_code = EXIT_OUTPUT


class StandinError(MlaunchError):
    """A stand-in program cannot use its input (URDF, world, model, arguments, parameters).

    The stand-in logs the message as one line and exits 1, as the real program would fail.
    """

    exit_code = EXIT_FAILURE
