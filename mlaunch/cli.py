"""The command line: argv -> Options -> load -> resolve -> run. The only place errors are printed.

Exit status (the table is mlaunch.errors'):
  0    every process ended and nothing required failed (or a Shutdown action ended the launch)
  1    a required process (on_exit=Shutdown / required=True) exited with a failure
  2    bad command line or launch file: missing file, syntax error, bad argument, failed
       substitution, missing package or executable (one line on stderr, no traceback)
  70   an internal error of mlaunch (a bug: --debug shows the traceback)
  128+N  mlaunch was stopped by signal N: 130 for Ctrl-C (SIGINT), 143 SIGTERM, 129 SIGHUP
"""

from __future__ import annotations

import argparse
import os
import sys

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Sequence
    from typing import Any

    from mlaunch.launch.launch_description import LaunchDescription, LaunchDescriptionEntity
    from mlaunch.ros.search import PackageSearch
    from mlaunch.run.lifeline import Lifeline
    from mlaunch.run.plan import ArgumentInfo, Plan
    from mlaunch.run.resolve import LabelCounter, ResolveOptions

# The private params folder of a run; other commands (export, LaunchService) make one too.
from mlaunch.run.lifeline import private_temp_dir, remove_private_dir  # noqa: E402, F401

SUBCOMMANDS = {
    "test": "mlaunch.smoke",
    "convert": "mlaunch.ros1.convert",
    "export": "mlaunch.export",
}


class Options:
    """What the command line asked for (a plain class: dataclasses cost ~8 ms to import)."""

    def __init__(
        self,
        target: str,
        second: str | None = None,
        arguments: dict[str, str] | None = None,
        show_args: bool = False,
        print_plan: bool = False,
        check: bool = False,
        debug: bool = False,
        use_sim_time: bool | None = None,
        package_path: list[str] | None = None,
        standins: bool = True,
        status: bool = False,
        quiet: bool = False,
        color: bool | None = None,
        log_max_bytes: int | None = None,
        log_keep: int | None = None,
    ) -> None:
        self.target = target
        self.second = second
        self.arguments: dict[str, str] = {} if arguments is None else arguments
        # The name:=value words as given, in order: what a launch file finds in sys.argv.
        self.launch_argv: list[str] = []
        self.show_args = show_args
        self.print_plan = print_plan
        self.check = check
        self.debug = debug
        self.use_sim_time = use_sim_time
        self.package_path: list[str] = [] if package_path is None else package_path
        self.standins = standins
        self.status = status
        self.quiet = quiet
        self.color = color
        self.log_max_bytes = log_max_bytes
        self.log_keep = log_keep


class _HelpFormatter(argparse.HelpFormatter):
    """argparse's formatter, sized without shutil.

    argparse builds a formatter for every add_argument(), and its default one imports shutil
    (with zlib, bz2, lzma: ~2 ms) only to ask for the terminal width.
    """

    def __init__(
        self,
        prog: str,
        indent_increment: int = 2,
        max_help_position: int = 24,
        width: int | None = None,
    ) -> None:
        if width is None:
            width = _help_width()
        super().__init__(prog, indent_increment, max_help_position, width)


def _help_width() -> int:
    """What argparse would use: $COLUMNS, else the terminal's width, else 80; minus 2."""
    try:
        columns = int(os.environ.get("COLUMNS", ""))
    except ValueError:
        columns = 0
    if columns <= 0:
        try:
            columns = os.get_terminal_size(sys.__stdout__.fileno()).columns  # type: ignore[union-attr]
        except (AttributeError, ValueError, OSError):
            columns = 0
    return (columns or 80) - 2


def build_parser(prog: str = "mlaunch") -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog=prog,
        formatter_class=_HelpFormatter,
        description="Run a ROS 2 launch file (Python, YAML, XML or ROS 1 XML) and supervise it.",
        epilog="Subcommands: 'mlaunch test FILE ...' (CI smoke run), 'mlaunch convert FILE' "
        "(ROS 1 -> ROS 2). Exit status: 0 ok, 1 a required process failed, 2 bad input, "
        "130 interrupted.",
    )
    parser.add_argument(
        "target", help="launch file, or package name followed by a launch file name"
    )
    parser.add_argument("rest", nargs="*", help="[launch file name] then name:=value arguments")
    view = parser.add_mutually_exclusive_group()
    view.add_argument(
        "-s",
        "--show-args",
        "--show-arguments",
        action="store_true",
        help="list the launch arguments and exit",
    )
    view.add_argument(
        "-p",
        "--print",
        "--print-description",
        dest="print_plan",
        action="store_true",
        help="print the resolved plan (argv, cwd, env, respawn, shutdown) and exit",
    )
    view.add_argument(
        "--check",
        action="store_true",
        help="report what ros2 launch (Jazzy) would reject or read differently in the file"
        " and the files it includes by path; exit 1 if anything",
    )
    parser.add_argument("-d", "--debug", action="store_true", help="tracebacks for errors")
    parser.add_argument(
        "-n", "--noninteractive", action="store_true", help="accepted for ros2 launch compatibility"
    )
    parser.add_argument(
        "-a",
        "--show-all-subprocesses-output",
        action="store_true",
        help="print every process's output (output=both)",
    )
    parser.add_argument(
        "--use-sim-time",
        action="store_true",
        default=None,
        help="set the parameter use_sim_time on every node (use_sim_time:=true is an ordinary"
        " launch argument, as in ros2 launch)",
    )
    parser.add_argument(
        "--package-path",
        action="append",
        default=[],
        metavar="DIR",
        help="extra folders to find source packages in (repeatable; also $MLAUNCH_PACKAGE_PATH)",
    )
    parser.add_argument(
        "--no-standins",
        action="store_true",
        help="never replace a missing program with mlaunch's stand-in",
    )
    parser.add_argument(
        "--launch-prefix", help="prefix for every process, e.g. 'gdb -ex run --args'"
    )
    parser.add_argument(
        "--launch-prefix-filter", help="regex on executable names the prefix applies to"
    )
    parser.add_argument("--status", action="store_true", help="live status view of the processes")
    parser.add_argument(
        "-q", "--quiet", action="store_true", help="only warnings and errors from mlaunch itself"
    )
    parser.add_argument("--color", choices=("auto", "always", "never"), default="auto")
    parser.add_argument(
        "--log-max-bytes", type=int, default=None, help="rotate log files at this size"
    )
    parser.add_argument(
        "--log-keep",
        default=None,
        metavar="N|all",
        help="rotated parts kept per log file (default 3; all: never drop a line)",
    )
    return parser


# Options that take a value: the token after them is theirs even if it contains ":=".
VALUE_OPTIONS = frozenset(
    {
        "--package-path",
        "--launch-prefix",
        "--launch-prefix-filter",
        "--color",
        "--log-max-bytes",
        "--log-keep",
    }
)


def split_launch_arguments(argv: Sequence[str]) -> tuple[list[str], list[str]]:
    """(name:=value items, everything else), so argparse never has to interleave them.

    parse_intermixed_args does that too, at ~6 ms a run; a launch's start-up budget is 60 ms.
    """
    launch_args: list[str] = []
    others: list[str] = []
    previous = ""
    for item in argv:
        if ":=" in item and not item.startswith("-") and previous not in VALUE_OPTIONS:
            launch_args.append(item)
        else:
            others.append(item)
        previous = item
    return launch_args, others


def parse_options(argv: Sequence[str]) -> Options:
    from mlaunch.errors import UsageError

    launch_args, others = split_launch_arguments(argv)
    parser = build_parser()
    ns, extras = parser.parse_known_args(others)
    unknown = [e for e in extras if e.startswith("-")]
    if unknown:
        parser.error(f"unrecognized arguments: {' '.join(unknown)}")
    ns.rest = [*ns.rest, *extras, *launch_args]
    opts = Options(
        target=ns.target,
        show_args=ns.show_args,
        print_plan=ns.print_plan,
        check=ns.check,
        debug=ns.debug,
        use_sim_time=ns.use_sim_time,
        package_path=list(ns.package_path),
        standins=not ns.no_standins,
        status=ns.status,
        quiet=ns.quiet,
        color={"auto": None, "always": True, "never": False}[ns.color],
        log_max_bytes=ns.log_max_bytes,
        log_keep=_log_keep(ns.log_keep),
    )
    rest = list(ns.rest)
    if rest and ":=" not in rest[0] and not os.path.isfile(ns.target):
        opts.second = rest.pop(0)
    for item in rest:
        name, sep, value = item.partition(":=")
        if not sep or not name or (not value and not item.endswith(":=")):
            raise UsageError(
                f"malformed launch argument {item!r}, expected format '<name>:=<value>'"
            )
        opts.arguments[name] = value  # last one wins
        opts.launch_argv.append(item)
    if ns.launch_prefix:
        opts.arguments["launch-prefix"] = ns.launch_prefix
    if ns.launch_prefix_filter:
        if not ns.launch_prefix:
            raise UsageError("--launch-prefix-filter needs --launch-prefix")
        opts.arguments["launch-prefix-filter"] = ns.launch_prefix_filter
    if ns.show_all_subprocesses_output:
        os.environ["OVERRIDE_LAUNCH_PROCESS_OUTPUT"] = "both"
    return opts


def _log_keep(value: str | None) -> int | None:
    """--log-keep: a count of rotated parts, or ``all`` (logfiles.ALL)."""
    if value is None:
        return None
    if value == "all":
        return -1
    if value.isdigit():
        return int(value)
    from mlaunch.errors import UsageError

    raise UsageError(
        f"--log-keep is {value!r}; valid: a number of rotated files (0 or more), or all"
    )


def find_launch_file(opts: Options) -> str:
    """The launch file path: a file, or PKG FILE looked up in the package's share folder."""
    from mlaunch.errors import LaunchFileError

    if opts.second is None:
        if not os.path.exists(opts.target):
            raise LaunchFileError(f"launch file {opts.target!r} does not exist")
        return os.path.abspath(opts.target)
    from mlaunch.ros import packages

    return packages.find_launch_file(opts.target, opts.second)


def main(argv: Sequence[str] | None = None) -> int:
    """``mlaunch ...`` and its subcommands: the one place errors are caught and printed."""
    args = list(sys.argv[1:] if argv is None else argv)
    debug = "--debug" in args or "-d" in args
    try:
        if args and args[0] in SUBCOMMANDS and not os.path.isfile(args[0]):
            import importlib

            return int(importlib.import_module(SUBCOMMANDS[args[0]]).command(args[1:]))
        return run_cli(args)
    except BrokenPipeError:
        from mlaunch.run.lifeline import stdout_gone

        return stdout_gone()
    except (Exception, KeyboardInterrupt) as e:  # KeyboardInterrupt: Ctrl-C, lifeline.Stopped
        return report_error(e, debug)


def report_error(error: BaseException, debug: bool) -> int:
    """The error printed once (see mlaunch.errors.report); its exit status."""
    from mlaunch.errors import report

    return report(error, debug=debug)


def package_search(opts: Options, launch_file: str | None) -> PackageSearch:
    """Where this run looks for ROS packages: --package-path, the launch file, the environment."""
    from mlaunch.ros.search import PackageSearch

    return PackageSearch(opts.package_path, launch_file, os.environ)


def load_target(opts: Options) -> tuple[str, LaunchDescription]:
    """The launch file the command line names (a path, or PKG FILE) and its description."""
    from mlaunch.ros.search import searching

    # `mlaunch PKG FILE` looks the package up with the search settings, before there is a file.
    given = os.path.abspath(opts.target) if opts.second is None else None
    with searching(package_search(opts, given if given and os.path.exists(given) else None)):
        path = find_launch_file(opts)
    from mlaunch import frontends
    from mlaunch.frontends.python import set_launch_argv

    set_launch_argv(opts.target, opts.second, opts.launch_argv)

    # Launch-file code run while loading (get_package_share_directory) sees the same search.
    with searching(package_search(opts, path)):
        return path, frontends.load(path)


def resolve_for_run(
    opts: Options,
    path: str,
    description: LaunchDescriptionEntity,
    *,
    temp_dir: str,
    log_dir: str,
) -> tuple[Plan, ResolveOptions, LabelCounter]:
    """(plan, resolve options, label counter) for a run of ``description`` as opts say."""
    from mlaunch.run.resolve import LabelCounter, ResolveOptions, resolve

    options = ResolveOptions(
        standins=opts.standins, packages=package_search(opts, path), temp_dir=temp_dir
    )
    if opts.use_sim_time is not None:
        from mlaunch.launch_ros.actions import with_use_sim_time

        description = with_use_sim_time(description, opts.use_sim_time)
    labels = LabelCounter()
    plan = resolve(
        description,
        path=path,
        arguments=opts.arguments,
        environ=dict(os.environ),
        log_dir=log_dir,
        options=options,
        labels=labels,
    )
    return plan, options, labels


def run_cli(argv: Sequence[str]) -> int:
    from mlaunch.run.lifeline import Lifeline, write_stdout

    opts = parse_options(argv)
    if opts.check:
        return check_target(opts)
    # From here on a launch file's code and substitutions may start processes: signals, the
    # guard and the run's marker cover them (a slow Command is when SIGTERM tends to arrive).
    with Lifeline() as life:
        path, description = load_target(opts)
        if opts.show_args:
            from mlaunch.ros.search import searching
            from mlaunch.run.resolve import collect_arguments

            with searching(package_search(opts, path)):
                infos = collect_arguments(
                    description, path=path, arguments=opts.arguments, environ=os.environ
                )
            write_stdout(format_arguments(infos))
            return 0
        return launch(opts, path, description, life)


def check_target(opts: Options) -> int:
    """``--check``: the portability report of the launch file, without loading or running it."""
    from mlaunch.portability import report
    from mlaunch.ros.search import searching

    with searching(package_search(opts, None)):
        return report(find_launch_file(opts), sys.stdout)


def launch(opts: Options, path: str, description: LaunchDescriptionEntity, life: Lifeline) -> int:
    log_dir = ""
    if not opts.print_plan:
        from mlaunch.run.logfiles import make_run_log_dir

        log_dir = make_run_log_dir(os.environ)
    plan, options, labels = resolve_for_run(
        opts, path, description, temp_dir=life.temp_dir, log_dir=log_dir
    )
    if opts.print_plan:
        from mlaunch.run.describe import describe_plan
        from mlaunch.run.lifeline import write_stdout

        write_stdout(describe_plan(plan, path))
        return 0
    return supervise(opts, plan, options, labels, log_dir, life)


def supervise(
    opts: Options,
    plan: Plan,
    options: ResolveOptions,
    labels: LabelCounter,
    log_dir: str,
    life: Lifeline,
) -> int:
    from mlaunch.errors import UsageError
    from mlaunch.run.logfiles import DEFAULT_ROTATE_BYTES, DEFAULT_ROTATE_KEEP
    from mlaunch.run.output import Printer, stdout_is_color_terminal
    from mlaunch.run.supervisor import Supervisor

    if opts.log_max_bytes is not None and opts.log_max_bytes < 0:
        raise UsageError(
            f"--log-max-bytes is {opts.log_max_bytes}; valid: 0 (never rotate) or more"
        )
    guard, run_id = life.guard, life.run_id
    color = stdout_is_color_terminal(os.environ) if opts.color is None else opts.color
    rotate = DEFAULT_ROTATE_BYTES if opts.log_max_bytes is None else opts.log_max_bytes
    keep = getattr(opts, "log_keep", None)
    printer = Printer(
        color=color,
        log_dir=log_dir,
        quiet=opts.quiet,
        rotate_bytes=rotate,
        rotate_keep=DEFAULT_ROTATE_KEEP if keep is None else keep,
    )
    printer.message("INFO", "launch", f"All log files can be found below {log_dir}")
    spawner = _spawner(plan, labels, run_id)
    supervisor = Supervisor(
        plan,
        printer,
        options=options,
        labels=labels,
        guard=guard,
        run_id=run_id,
        cgroup=life.cgroup,
        **({} if spawner is None else {"spawner": spawner}),
    )
    extensions: list[object] = []
    try:
        if spawner is not None:
            spawner.connect(plan.processes())
        extensions = _extensions(opts, supervisor)
        life.block()  # until the supervisor's own handlers are in
        try:
            code = supervisor.run()
        finally:
            life.hand_over()
    finally:
        for ext in extensions:
            close = getattr(ext, "close", None)
            if close is not None:
                close()
        if spawner is not None:
            spawner.close()
        printer.close()
        # Everything the run started has ended (run() kills what is left even when it fails).
        if guard is not None:
            guard.close()
    return code


def _spawner(plan: object, labels: object, run_id: str) -> Any:
    """The remote-process spawner when the launch declared other machines, else None."""
    if not getattr(labels, "machines", None):
        return None  # no Machine in the launch: mlaunch.machines is never imported
    from mlaunch.machines.spec import remote_machines

    if not remote_machines(labels):
        return None
    from mlaunch.machines.remote import Spawner
    from mlaunch.run.guard import MARKER

    return Spawner(os.environ, {MARKER: run_id})


def _extensions(opts: Options, supervisor: object) -> list[object]:
    """Optional parts that attach to a running supervisor (status view, lifecycle, summary)."""
    attached: list[object] = []
    try:
        from mlaunch.run import extensions
    except ImportError:
        return attached
    for attach in extensions.ATTACH:
        ext = attach(opts, supervisor)
        if ext is not None:
            attached.append(ext)
    return attached


def format_arguments(infos: Sequence[ArgumentInfo]) -> str:
    """The --show-args table: name, default, description (and choices), conditional marked."""
    if not infos:
        return "No arguments.\n"
    import textwrap

    rows = []
    any_conditional = False
    for info in infos:
        name = info.name + ("*" if info.conditional else "")
        any_conditional |= info.conditional
        default = "(required)" if info.default is None else repr(info.default)
        rows.append((name, default, info.description))
    w_name = max(len("name"), *(len(r[0]) for r in rows))
    w_def = min(36, max(len("default"), *(len(r[1]) for r in rows)))
    width = max(40, _terminal_width() - w_name - w_def - 6)
    out = ["Arguments (pass arguments as '<name>:=<value>'):", ""]
    out.append(f"  {'name':<{w_name}}  {'default':<{w_def}}  description")
    out.append(f"  {'-' * w_name}  {'-' * w_def}  {'-' * min(width, 40)}")
    for name, default, description in rows:
        lines = textwrap.wrap(description, width) or [""]
        shown = default if len(default) <= w_def else default[: w_def - 3] + "..."
        out.append(f"  {name:<{w_name}}  {shown:<{w_def}}  {lines[0]}")
        pad = " " * (w_name + w_def + 6)
        out.extend(pad + line for line in lines[1:])
    if any_conditional:
        out += ["", "* argument(s) which are only used if specific conditions occur"]
    return "\n".join(out) + "\n"


def _terminal_width() -> int:
    try:
        return os.get_terminal_size(1).columns
    except OSError:
        return 100


def program() -> None:
    """The ``mlaunch`` program: main(), then exit without interpreter teardown.

    By the time main() returns, the printer is closed, the guard reaped and the temp dir gone;
    only stdio buffers remain, so flushing them and calling os._exit skips ~8 ms of teardown
    between the last child's death and mlaunch's. Tests call main() instead.
    """
    from mlaunch.run.lifeline import ensure_std_streams

    ensure_std_streams()  # a closed stdout (mlaunch FILE >&-) must not lend its number to a file
    try:
        code = main()
    except SystemExit as e:  # argparse's usage errors and --help
        code = e.code if isinstance(e.code, int) else (0 if e.code is None else 2)
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):  # a closed pipe (mlaunch ... | head)
            pass
    os._exit(code)


if __name__ == "__main__":
    program()
