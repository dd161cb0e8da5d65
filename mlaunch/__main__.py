"""``python -m mlaunch``: the same as the ``mlaunch`` command."""

from mlaunch.cli import program

program()
