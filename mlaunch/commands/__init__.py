"""The subcommands of mlaunch, in one typed table: ``test``, ``convert``, ``export``, ``ctl``.

colcon's ``VerbExtensionPoint`` model: a subcommand is an object with its name, a line of help,
``parser()`` (its whole command line, which shell completion completes on) and ``main(args)``
(its work; it raises mlaunch's errors, which ``mlaunch.cli.main`` prints once). ``subcommands()``
lists them; the CLI dispatches through it and completion reads it, so a new subcommand is one
class here and one line in ``subcommands()``. Nothing here calls back into the CLI.

This module is on the path to the first child of every launch (the CLI asks it whether the
first word is a subcommand): it imports nothing, each subcommand's module is imported only when
that subcommand runs or is completed.
"""

from __future__ import annotations

from abc import ABC, abstractmethod

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    import argparse
    from collections.abc import Sequence


class Subcommand(ABC):
    """One subcommand of ``mlaunch``: ``mlaunch NAME ARGS``."""

    name = ""
    help = ""

    @abstractmethod
    def parser(self) -> argparse.ArgumentParser:
        """Its whole command line (for completion and ``--help``)."""

    @abstractmethod
    def main(self, args: Sequence[str]) -> int:
        """Run it with ``args`` (what follows its name); the exit status. Raises on failure."""


class Test(Subcommand):
    name = "test"
    help = "CI smoke run of a launch file: up, ready, held, shut down"

    def parser(self) -> argparse.ArgumentParser:
        from mlaunch.app.options import build_parser
        from mlaunch.smoke.settings import build_parser as settings_parser

        return with_options_of(build_parser(prog="mlaunch test"), settings_parser())

    def main(self, args: Sequence[str]) -> int:
        from mlaunch.commands.smoke import command

        return command(args)


class Convert(Subcommand):
    name = "convert"
    help = "a ROS 1 roslaunch file written as a ROS 2 launch file"

    def parser(self) -> argparse.ArgumentParser:
        from mlaunch.commands.convert import build_parser

        return build_parser()

    def main(self, args: Sequence[str]) -> int:
        from mlaunch.commands.convert import command

        return command(args)


class Export(Subcommand):
    name = "export"
    help = "hand a launch to systemd (units) or to Ansible (a playbook for a fleet)"

    def parser(self) -> argparse.ArgumentParser:
        from mlaunch.app.options import build_parser
        from mlaunch.commands.export import build_parser as export_parser

        return with_options_of(build_parser(prog="mlaunch export"), export_parser())

    def main(self, args: Sequence[str]) -> int:
        from mlaunch.commands.export import command

        return command(args)


class Ctl(Subcommand):
    name = "ctl"
    help = "control a running launch: list, stop, start, restart, mute, unmute, logs, wait-ready"

    def parser(self) -> argparse.ArgumentParser:
        from mlaunch.commands.ctl import parser

        return parser()

    def main(self, args: Sequence[str]) -> int:
        from mlaunch.commands.ctl import command

        return command(args)


def subcommands() -> dict[str, Subcommand]:
    """Every subcommand by name, in the order ``mlaunch --help`` and completion list them."""
    return {sub.name: sub for sub in (Test(), Convert(), Export(), Ctl())}


def with_options_of(
    parser: argparse.ArgumentParser, other: argparse.ArgumentParser
) -> argparse.ArgumentParser:
    """``parser`` (mlaunch FILE's) with ``other``'s options added: a subcommand that runs a
    launch file takes both."""
    known = set(parser._option_string_actions)
    for action in other._actions:
        if action.option_strings and not known.intersection(action.option_strings):
            parser._add_action(action)
    return parser
