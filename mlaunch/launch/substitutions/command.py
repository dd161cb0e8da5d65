"""``launch.substitutions.command``: the output of a command.

subprocess (~3 ms, with selectors and threading) is imported only when a Command runs.
"""

from __future__ import annotations

import os
from collections.abc import Callable

from mlaunch.launch.substitution import (
    SomeSubstitutionsType,
    Substitution,
    describe,
    normalize,
    perform_substitutions,
)
from mlaunch.plan.errors import SubstitutionFailure

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

    from mlaunch.launch.launch_context import LaunchContext


# Programs Command() may run inside mlaunch instead of spawning them (xacro: no interpreter start).
# Each entry takes (argv, context) and returns (returncode, stdout, stderr).
InProcessCommand = Callable[[list[str], "LaunchContext"], tuple[int, str, str]]


IN_PROCESS_COMMANDS: dict[str, InProcessCommand] = {}


class Command(Substitution):
    """The standard output of a command run at resolve time (``$(command 'cmd' [on_stderr])``).

    As in ROS 2, a non-zero exit fails and, by default, so does any output on stderr
    (``on_stderr``: ``fail``, ``warn``, ``ignore`` or ``capture``).
    """

    ON_STDERR = ("fail", "warn", "ignore", "capture")

    def __init__(self, command: SomeSubstitutionsType, *, on_stderr: Any = "fail") -> None:
        self.command = normalize(command)
        self.on_stderr = normalize(on_stderr)

    def perform(self, context: LaunchContext) -> str:
        text = perform_substitutions(context, self.command)
        on_stderr = perform_substitutions(context, self.on_stderr)
        if on_stderr not in self.ON_STDERR:
            raise SubstitutionFailure(
                f"Command on_stderr is {on_stderr!r}; valid: {', '.join(self.ON_STDERR)}"
            )
        import shlex

        try:
            argv = shlex.split(text)
        except ValueError as e:
            raise SubstitutionFailure(f"cannot split command {text!r}: {e}")
        if not argv:
            raise SubstitutionFailure("Command is empty")
        rc, out, err = run_command(argv, context)
        if rc != 0:
            detail = err.strip().splitlines()[-1] if err.strip() else f"exit status {rc}"
            # launch's words first, then what mlaunch adds (the status, stderr's last line)
            raise SubstitutionFailure(
                f"executed command failed. Command: {text} (exit status {rc}: {detail})"
            )
        if err:
            if on_stderr == "fail":
                raise SubstitutionFailure(
                    f"executed command showed stderr output. Command: {text}\n"
                    f"Captured stderr output: {err.strip()[:500]}\n"
                    "(the command wrote to stderr: pass on_stderr='warn' or 'ignore' to accept"
                    " that)"
                )
            if on_stderr == "warn":
                context.warn(f"command {text!r} wrote to stderr: {err.strip()}")
            elif on_stderr == "capture":
                out += err
        return out

    def describe(self) -> str:
        return f"Command({describe(self.command)})"


def run_command(argv: list[str], context: LaunchContext) -> tuple[int, str, str]:
    """Run a command for Command(): in-process when a handler is registered, else spawned."""
    handler = IN_PROCESS_COMMANDS.get(os.path.basename(argv[0]))
    if handler is not None:
        return handler(argv, context)
    import subprocess

    try:
        done = subprocess.run(
            argv,
            capture_output=True,
            env=dict(context.environment),
            stdin=subprocess.DEVNULL,
            check=False,
        )
    except FileNotFoundError:
        raise SubstitutionFailure(f"file not found: command {argv[0]!r} not found on the PATH")
    except OSError as e:
        raise SubstitutionFailure(f"cannot run command {argv[0]!r}: {e.strerror}")
    return (
        done.returncode,
        done.stdout.decode("utf-8", "replace"),
        done.stderr.decode("utf-8", "replace"),
    )
