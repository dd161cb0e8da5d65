"""The one exit-status table, the one place errors are printed, and honest ImportErrors."""

from __future__ import annotations

import signal
import subprocess
import sys
from pathlib import Path

import pytest
from procutil import clean_env

from mlaunch.plan import errors
from mlaunch.plan.errors import (
    EXIT_FAILURE,
    EXIT_INTERNAL,
    EXIT_INTERRUPTED,
    EXIT_OK,
    EXIT_USAGE,
    LaunchFileError,
    StandinError,
    exit_for_signal,
    exit_status,
)


def test_the_exit_status_table() -> None:
    assert (EXIT_OK, EXIT_FAILURE, EXIT_USAGE, EXIT_INTERNAL) == (0, 1, 2, 70)
    assert EXIT_INTERRUPTED == exit_for_signal(signal.SIGINT) == 130
    assert exit_for_signal(signal.SIGTERM) == 143 and exit_for_signal(signal.SIGHUP) == 129
    assert exit_status(LaunchFileError("bad")) == EXIT_USAGE
    assert exit_status(StandinError("bad urdf")) == EXIT_FAILURE
    assert exit_status(KeyboardInterrupt()) == EXIT_INTERRUPTED
    assert exit_status(ZeroDivisionError("x")) == EXIT_INTERNAL


def test_report_prints_one_line_and_says_what_is_a_bug(capsys: pytest.CaptureFixture[str]) -> None:
    where = LaunchFileError("no such tag 'nod'", where="a.launch.xml:3")
    assert errors.report(where, debug=False) == 2
    assert capsys.readouterr().err == "mlaunch: error: a.launch.xml:3: no such tag 'nod'\n"
    assert errors.report(KeyError("k"), debug=False, prog="launch_test") == 70
    assert capsys.readouterr().err == (
        "launch_test: internal error: KeyError: 'k' (run with --debug for the traceback)\n"
    )


def test_every_standin_error_has_the_one_base() -> None:
    from mlaunch.standins import diffdrive, rsp, sim, spawn, stp, urdf, viewer, world

    kinds = [
        diffdrive.ModelError,
        rsp.ParameterError,
        sim.SimUsageError,
        spawn.SpawnError,
        stp.UsageError,
        urdf.UrdfError,
        viewer.ViewerError,
        world.WorldError,
    ]
    assert all(issubclass(kind, StandinError) for kind in kinds)
    assert issubclass(urdf.UrdfError, ValueError)  # still caught where a ValueError was


def run_main(code: str, *args: str) -> subprocess.CompletedProcess[str]:
    script = f"import sys\n{code}\nfrom mlaunch.cli import main\nsys.exit(main(sys.argv[1:]))\n"
    return subprocess.run(
        [sys.executable, "-c", script, *args],
        capture_output=True,
        text=True,
        env=clean_env(),
        timeout=60,
    )


def test_a_missing_dependency_is_named(tmp_path: Path) -> None:
    path = tmp_path / "one.launch.yaml"
    path.write_text("launch:\n- executable: {cmd: echo hi}\n")
    done = run_main("sys.modules['yaml'] = None  # PyYAML not installed", str(path))
    assert done.returncode == EXIT_USAGE, done.stderr
    assert "needs the Python package 'yaml', which is not installed" in done.stderr
    assert "no frontend" not in done.stderr


def test_a_missing_part_of_mlaunch_is_an_internal_error(tmp_path: Path) -> None:
    path = tmp_path / "one.launch.yaml"
    path.write_text("launch:\n- executable: {cmd: echo hi}\n")
    done = run_main("sys.modules['mlaunch.frontends.yaml'] = None", str(path))
    assert done.returncode == EXIT_INTERNAL, done.stderr
    assert "internal error: ModuleNotFoundError" in done.stderr


def test_subcommand_errors_go_through_the_one_main(tmp_path: Path) -> None:
    missing = str(tmp_path / "missing.launch")
    done = run_main("", "convert", missing)
    assert done.returncode == EXIT_USAGE
    assert done.stderr == f"mlaunch: error: launch file {missing!r} does not exist\n"
    done = run_main("", "test")
    assert done.returncode == EXIT_USAGE
    assert "a launch file is needed" in done.stderr


def test_every_subcommand_is_in_the_table_the_cli_and_completion_read() -> None:
    from mlaunch.cli import completion
    from mlaunch.commands import Subcommand, subcommands

    table = subcommands()
    assert list(table) == ["test", "convert", "export", "ctl"]
    for name, sub in table.items():
        assert isinstance(sub, Subcommand) and sub.name == name and sub.help, name
        assert sub.parser().prog == f"mlaunch {name}", name
        words = completion.parser_for(["mlaunch", name])
        assert words._subparsers is not None, name  # completes on the subcommand's parser
    assert set(table) <= set(completion.target_completer("", None))
