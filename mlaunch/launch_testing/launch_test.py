"""``launch_test FILE.test.py [name:=value ...]`` and ``mlaunch test FILE.test.py``.

Loads a launch_testing file, runs each of its launches with its tests (see test_runner), prints
unittest's report, optionally writes a JUnit report, and exits 0 when every test passed, 1 when
one failed, 2 for a bad command line or a file that is not a launch test.
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import re
import sys

from mlaunch.plan.errors import EXIT_FAILURE, EXIT_INTERRUPTED, EXIT_OK, EXIT_USAGE

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Sequence
    from types import ModuleType

    from mlaunch.launch.launch_description import LaunchDescriptionEntity

# mlaunch.plan.errors' table: a launch test's own errors (its file, its arguments) are bad input.
EXIT_PASS = EXIT_OK
EXIT_FAIL = EXIT_FAILURE

_GENERATE = re.compile(rb"^\s*(async\s+)?def\s+generate_test_description\s*\(", re.MULTILINE)


def is_launch_test_file(path: str) -> bool:
    """Whether ``path`` is a Python file defining generate_test_description (a launch test)."""
    if not path.endswith(".py") or not os.path.isfile(path):
        return False
    try:
        with open(path, "rb") as f:
            return _GENERATE.search(f.read()) is not None
    except OSError:
        return False


def build_parser(prog: str = "launch_test") -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog=prog,
        description="Run a launch_testing file: launch it, run its tests, report.",
        epilog="Exit status: 0 every test passed, 1 a test failed, 2 bad input.",
    )
    parser.add_argument("launch_test_file", help="path to the launch test (FILE.test.py)")
    parser.add_argument(
        "--package-name", default=None, help="package the test is in (names the JUnit report)"
    )
    parser.add_argument("-v", "--verbose", action="store_true", help="verbose output")
    parser.add_argument(
        "-s",
        "--show-args",
        "--show-arguments",
        action="store_true",
        help="show the arguments the launch test takes",
    )
    parser.add_argument(
        "launch_arguments", nargs="*", help="arguments as '<name>:=<value>' (last one wins)"
    )
    parser.add_argument(
        "--junit-xml",
        "--junit",
        dest="xmlpath",
        default=None,
        help="write a JUnit XML report to this path",
    )
    return parser


def load_module(name: str, path: str) -> ModuleType:
    """Import the test file as module ``name``, with the ROS 2 names served by mlaunch."""
    from mlaunch import compat

    compat.install()
    spec = importlib.util.spec_from_file_location(name, path)
    if spec is None or spec.loader is None:
        raise ValueError(f"{path}: cannot be loaded as a Python module")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def run(args: argparse.Namespace) -> int:
    from mlaunch.launch_testing.loader import load_test_runs
    from mlaunch.launch_testing.test_runner import LaunchTestRunner

    path = os.path.abspath(args.launch_test_file)
    if not os.path.isfile(path):
        raise FileNotFoundError(f"Test file '{args.launch_test_file}' does not exist")
    basename = os.path.splitext(os.path.basename(path))[0]
    package = args.package_name or basename
    module = load_module(package, path)
    runs = load_test_runs(module, name=f"{package}.{basename}.launch_tests")
    runner = LaunchTestRunner(runs, launch_file_arguments=args.launch_arguments, debug=args.verbose)
    runner.validate()
    if args.show_args:
        show_arguments(runs[0].launch_description(), path)
        return EXIT_PASS
    results = runner.run()
    if args.xmlpath:
        from mlaunch.launch_testing.junitxml import write_report

        write_report(args.xmlpath, f"{package}.{basename}", results)
    return EXIT_PASS if all(r.wasSuccessful() for r in results.values()) else EXIT_FAIL


def show_arguments(description: LaunchDescriptionEntity, path: str) -> None:
    from mlaunch.resolve.describe import format_arguments
    from mlaunch.resolve.resolver import collect_arguments

    infos = collect_arguments(description, path=path, arguments={}, environ=os.environ)
    sys.stdout.write(format_arguments(infos))


def main(argv: Sequence[str] | None = None, prog: str = "launch_test") -> int:
    parser = build_parser(prog)
    args = parser.parse_args(list(sys.argv[1:] if argv is None else argv))
    try:
        return run(args)
    except KeyboardInterrupt:
        return EXIT_INTERRUPTED
    except Exception as e:
        if args.verbose:
            import traceback

            traceback.print_exc()
        print(f"{prog}: error: {e}", file=sys.stderr)
        return EXIT_USAGE


def program() -> None:
    """The ``launch_test`` program."""
    sys.exit(main())


if __name__ == "__main__":
    program()
