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
    from xml.etree.ElementTree import ElementTree

    from mlaunch.launch_testing.test_runner import LaunchTestRunner

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


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """launch_test's arguments, on ``parser``."""
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


def build_parser(prog: str = "launch_test") -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog=prog,
        description="Run a launch_testing file: launch it, run its tests, report.",
        epilog="Exit status: 0 every test passed, 1 a test failed, 2 bad input.",
    )
    add_arguments(parser)
    return parser


def parse_arguments() -> tuple[argparse.ArgumentParser, argparse.Namespace]:
    """(parser, the parsed command line), as launch_testing's launch_test reads it."""
    parser = build_parser()
    return parser, parser.parse_args()


def load_module(name: str, path: str) -> ModuleType:
    """Import the test file as module ``name`` (the program that runs it serves the ROS 2 names:
    mlaunch.cli.launch_test, mlaunch test)."""
    spec = importlib.util.spec_from_file_location(name, path)
    if spec is None or spec.loader is None:
        raise ValueError(f"{path}: cannot be loaded as a Python module")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def run(
    parser: argparse.ArgumentParser,
    args: argparse.Namespace,
    test_runner_cls: type[LaunchTestRunner] | None = None,
) -> int:
    """Load the test file, run its launches and tests with ``test_runner_cls`` (launch_testing's
    LaunchTestRunner unless told: launch_testing_ros passes its own), write the JUnit report."""
    from mlaunch.launch_testing.loader import LoadTestsFromPythonModule
    from mlaunch.launch_testing.test_runner import LaunchTestRunner

    path = os.path.abspath(args.launch_test_file)
    if not os.path.isfile(path):
        raise FileNotFoundError(f"Test file '{args.launch_test_file}' does not exist")
    basename = os.path.splitext(os.path.basename(path))[0]
    package = args.package_name or basename
    module = load_module(package, path)
    runs = LoadTestsFromPythonModule(module, name=f"{package}.{basename}.launch_tests")
    runner = (test_runner_cls or LaunchTestRunner)(
        runs, launch_file_arguments=args.launch_arguments, debug=args.verbose
    )
    runner.validate()
    if args.show_args:
        from mlaunch.launch_testing.print_arguments import print_arguments_of_launch_description

        print_arguments_of_launch_description(
            launch_description=runs[0].get_launch_description(), path=path
        )
        return EXIT_PASS
    if args.xmlpath:
        from mlaunch.smoke import junit

        junit.check_target(args.xmlpath)  # found now, not after the tests ran
    results = runner.run()
    if args.xmlpath:
        from mlaunch.launch_testing.junitxml import unittestResultsToXml
        from mlaunch.smoke import junit

        report = unittestResultsToXml(test_results=results, name=f"{package}.{basename}")
        junit.write_report(args.xmlpath, _xml_bytes(report))
    return EXIT_PASS if all(r.wasSuccessful() for r in results.values()) else EXIT_FAIL


def _xml_bytes(report: ElementTree) -> bytes:
    """The report as ElementTree writes it to a file (declaration, UTF-8)."""
    import io

    out = io.BytesIO()
    report.write(out, encoding="utf-8", xml_declaration=True)
    return out.getvalue()


def main(argv: Sequence[str] | None = None, prog: str = "launch_test") -> int:
    parser = build_parser(prog)
    args = parser.parse_args(list(sys.argv[1:] if argv is None else argv))
    from mlaunch.ros.domain import Isolation

    try:
        with Isolation():  # a ROS domain of its own for the file, unless the user set one
            return run(parser, args)
    except KeyboardInterrupt:
        return EXIT_INTERRUPTED
    except Exception as e:
        if args.verbose:
            import traceback

            traceback.print_exc()
        print(f"{prog}: error: {e}", file=sys.stderr)
        return EXIT_USAGE


def program() -> None:
    """The ``launch_test`` program, once the ROS 2 names are served (mlaunch.cli.launch_test)."""
    sys.exit(main())
