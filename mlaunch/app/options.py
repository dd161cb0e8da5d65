"""What the command line asked for: ``mlaunch FILE ...``'s options, parsed.

``mlaunch test`` and ``mlaunch export`` take the same options after their own and parse them
here, so no subcommand imports the command line module back.
"""

from __future__ import annotations

import argparse
import os
import sys

from mlaunch.plan.argparser import ArgumentParser

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Mapping, Sequence

# The viewer stand-in's port variable (mlaunch.standins.viewer_config.PORT_ENV; not imported
# from there: that module loads dataclasses and typing, which a launch's start-up does without).
VIEWER_PORT_ENV = "MLAUNCH_VIEWER_PORT"


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
        self.capture = False  # --capture-at-definition (mlaunch.resolve.binding)
        self.scoped_parameters = False  # --scoped-parameters (mlaunch.launch_ros.scope)
        self.scoped_file_locals = False  # --scoped-file-locals (mlaunch.launch.file_locals)
        self.ros: int | None = None  # --ros1 / --ros2: how a roslaunch file runs (None: by env)
        self.package_path: list[str] = [] if package_path is None else package_path
        self.standins = standins
        self.status = status
        self.quiet = quiet
        self.color = color
        self.log_max_bytes = log_max_bytes
        self.log_keep = log_keep
        self.format = "text"  # --format: how --print and --show-args write (text or json)
        self.noninteractive = False  # -n: the launch context's noninteractive, as ros2 launch
        # --dashboard / --dashboard-port: the launch panel's own port (None: only the viewer's)
        self.dashboard_port: int | None = None
        self.metrics: str | None = None  # --metrics FILE.csv
        # --log-level [NAME:=]LEVEL, each given to every ROS process as --log-level
        self.log_levels: list[str] = []
        # --machine NAME: run only that machine's share (docs/machines.md); None: all of it
        self.machine: str | None = None
        # --no-cache (or MLAUNCH_NO_CACHE=1): load and resolve again, neither reading nor
        # writing the plan cache (mlaunch.app.plan_cache)
        self.cache = True


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
    parser = ArgumentParser(
        prog=prog,
        formatter_class=_HelpFormatter,
        description="Run a ROS 2 launch file (Python, YAML, XML or ROS 1 XML) and supervise it.",
        epilog="Subcommands: 'mlaunch test FILE ...' (CI smoke run), 'mlaunch convert FILE' "
        "(ROS 1 -> ROS 2), 'mlaunch export FILE' (systemd units), 'mlaunch ctl [RUN] list|stop|"
        "start|restart|mute|unmute|logs LABEL|unload|load|activate|... NODE' (control a running"
        " launch). "
        "Exit status: 0 ok, 1 a required process failed, 2 bad input, "
        "70 an internal error of mlaunch, 74 stdout cannot be written, 128+N stopped by signal N"
        " (130 Ctrl-C).",
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
    parser.add_argument(
        "--format",
        choices=("text", "json"),
        default="text",
        help="how --print and --show-args write: text to read (default), or json for tools"
        " (the schemas: docs/plan-json.md)",
    )
    parser.add_argument(
        "-d",
        "--debug",
        action="store_true",
        help="tracebacks for errors; what the plan cache did and why",
    )
    parser.add_argument(
        "--no-cache",
        action="store_true",
        help="load and resolve the launch file again, without the plan cache (also"
        " MLAUNCH_NO_CACHE=1; docs/plan-cache.md)",
    )
    parser.add_argument(
        "-n",
        "--noninteractive",
        action="store_true",
        help="as ros2 launch: a launch file's Shutdown due to SIGINT still sends its processes"
        " SIGINT (interactive: SIGTERM after sigterm_timeout)",
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
        "--capture-at-definition",
        action="store_true",
        help="resolve timers and event handlers with the values from where they are written,"
        " not (as ros2 launch) when they fire; per file: a comment"
        " 'mlaunch: capture-at-definition'",
    )
    ros = parser.add_mutually_exclusive_group()
    ros.add_argument(
        "--ros1",
        dest="ros",
        action="store_const",
        const=1,
        help="run a roslaunch file natively on ROS 1, as roslaunch does (a master, its parameter"
        " server, ROS 1 command lines); the default in a shell set up for ROS 1 (ROS_VERSION=1,"
        " ROS_DISTRO and ROS_MASTER_URI set)",
    )
    ros.add_argument(
        "--ros2",
        dest="ros",
        action="store_const",
        const=2,
        help="run a roslaunch file on ROS 2 (its nodes mapped to ROS 2 ones, docs/ros1.md),"
        " even in a shell set up for ROS 1",
    )
    parser.add_argument(
        "--scoped-parameters",
        action="store_true",
        help="keep SetParameter, SetParametersFromFile and SetRemap inside their scoped group"
        " (ros2 launch applies them after the group too); per file: a comment"
        " 'mlaunch: scoped-parameters'",
    )
    parser.add_argument(
        "--scoped-file-locals",
        action="store_true",
        help="keep an include's ThisLaunchFileDir/$(dirname) to the included file: its"
        " arguments and the actions after it get the includer's (ros2 launch, as ros2/launch#618,"
        " gives the included file's); per file: a comment 'mlaunch: scoped-file-locals'",
    )
    parser.add_argument(
        "--machine",
        metavar="NAME",
        help="run only the processes of machine NAME (a <machine>/Machine of the file) here,"
        " without ssh, as on that computer; 'local': those given no machine; the rest is left"
        " to the runs on the other machines (a fleet split, docs/machines.md)",
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
    parser.add_argument(
        "--status",
        action="store_true",
        help="a live table of the processes below their output; in a terminal, keys: up/down"
        " or j/k select a process, s start, x stop, r restart, m mute, u unmute it, l (or Enter)"
        " its last lines, Esc or q back to the table; Ctrl-C stops everything",
    )
    parser.add_argument(
        "--log-level",
        action="append",
        default=[],
        metavar="[NAME:=]LEVEL",
        help="the log level of every ROS process (its --ros-args --log-level), composable nodes"
        " through their container, and of mlaunch's own lines: LEVEL alone, or NAME:=LEVEL for"
        " the logger NAME ('launch' is mlaunch's own); repeatable; LEVEL is one of "
        + ", ".join(LOG_LEVELS),
    )
    parser.add_argument(
        "-q",
        "--quiet",
        action="store_true",
        help="only warnings and errors: mlaunch's, the processes' ROS log lines at WARN and above"
        " (either stream) and the rest of their stderr",
    )
    parser.add_argument(
        "--color",
        choices=("auto", "always", "never"),
        default="auto",
        help="color the output (default: auto, when stdout is a terminal and NO_COLOR is unset)",
    )
    parser.add_argument(
        "--log-max-bytes",
        type=int,
        default=None,
        metavar="N",
        help="rotate each log file at N bytes, 0 never (default: 67108864, 64 MiB)",
    )
    parser.add_argument(
        "--viewer-port",
        metavar="PORT",
        help="port of the viewer stand-in's page on 127.0.0.1 (default: any free port;"
        f" also ${VIEWER_PORT_ENV})",
    )
    parser.add_argument(
        "--dashboard",
        action="store_true",
        help="serve the launch panel (every process, its output, the controls) on 127.0.0.1"
        " (a run with the viewer stand-in has it on the viewer's page anyway)",
    )
    parser.add_argument(
        "--dashboard-port",
        metavar="PORT",
        help="the launch panel's port on 127.0.0.1 (implies --dashboard; default: any free port)",
    )
    parser.add_argument(
        "--metrics",
        metavar="FILE.csv",
        help="write each process's CPU, memory, threads and open files every second to FILE.csv,"
        " and a report with plots to FILE.html at the end",
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {_version()}")
    parser.add_argument(
        "--log-keep",
        default=None,
        metavar="N|all",
        help="rotated parts kept per log file (default 3; all: never drop a line)",
    )
    return parser


def _version() -> str:
    from mlaunch import __version__

    return __version__


# Options that take a value: the token after them is theirs even if it contains ":=".
VALUE_OPTIONS = frozenset(
    {
        "--log-level",
        "--package-path",
        "--launch-prefix",
        "--launch-prefix-filter",
        "--color",
        "--format",
        "--log-max-bytes",
        "--log-keep",
        "--viewer-port",
        "--dashboard-port",
        "--metrics",
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


# rcutils' severities, as --ros-args --log-level takes them.
LOG_LEVELS = ("debug", "info", "warn", "error", "fatal")


def log_level(item: str) -> str:
    """``--log-level [NAME:=]LEVEL`` checked, LEVEL in lower case (``warning`` is ``warn``)."""
    from mlaunch.plan.errors import UsageError, did_you_mean

    name, sep, level = item.rpartition(":=")
    level = level.strip().lower()
    level = "warn" if level == "warning" else level
    if level not in LOG_LEVELS or (sep and not name):
        raise UsageError(
            f"--log-level {item!r}: expected LEVEL or NAME:=LEVEL, LEVEL one of"
            f" {', '.join(LOG_LEVELS)}{did_you_mean(level, LOG_LEVELS)}"
        )
    return f"{name}:={level}" if sep else level


def own_log_level(levels: Sequence[str]) -> str | None:
    """The level mlaunch's own lines follow: the last one given alone or for 'launch'."""
    own = [lvl.rpartition(":=")[2] for lvl in levels if lvl.rpartition(":=")[0] in ("", "launch")]
    return own[-1] if own else None


def parse_options(argv: Sequence[str]) -> Options:
    from mlaunch.plan.errors import UsageError

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
    opts.capture = ns.capture_at_definition
    opts.cache = not ns.no_cache
    opts.log_levels = [log_level(item) for item in ns.log_level]
    opts.noninteractive = ns.noninteractive
    opts.format = ns.format
    if opts.format != "text" and not (opts.print_plan or opts.show_args):
        raise UsageError(
            f"--format {opts.format} is for --print (-p) and --show-args (-s): the plan or the"
            f" arguments as {opts.format}"
        )
    opts.scoped_parameters = ns.scoped_parameters
    opts.scoped_file_locals = ns.scoped_file_locals
    opts.ros = ns.ros
    if ns.machine is not None:
        from mlaunch.plan.machine import check_name

        problem = check_name(ns.machine)
        if problem is not None:
            raise UsageError(f"--machine {ns.machine!r}: {problem}")
        opts.machine = ns.machine
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
    if ns.viewer_port is not None:
        # The viewer stand-in reads it from its environment, as when the variable is set.
        os.environ[VIEWER_PORT_ENV] = str(_viewer_port(ns.viewer_port))
    if ns.dashboard or ns.dashboard_port is not None:
        opts.dashboard_port = _port("--dashboard-port", ns.dashboard_port or "0")
    if ns.metrics is not None:
        opts.metrics = _metrics_file(ns.metrics)
    return opts


def _metrics_file(value: str) -> str:
    """--metrics: a file that can be written (its folder exists), as an absolute path."""
    from mlaunch.plan.errors import UsageError

    path = os.path.abspath(value)
    folder = os.path.dirname(path)
    if not value or os.path.isdir(path) or not os.path.isdir(folder):
        raise UsageError(
            f"--metrics {value!r}: not a file in an existing folder; valid: a path such as"
            " run.csv (the report goes beside it, run.html)"
        )
    if not os.access(folder, os.W_OK) or (os.path.exists(path) and not os.access(path, os.W_OK)):
        raise UsageError(f"--metrics {value!r}: {path} cannot be written")
    return path


def _viewer_port(value: str) -> int:
    """--viewer-port: 0 (any free port) or a port of 127.0.0.1 that nothing listens on now."""
    return _port("--viewer-port", value)


def _port(option: str, value: str) -> int:
    """``option``'s value: 0 (any free port) or a port of 127.0.0.1 nothing listens on now."""
    from mlaunch.plan.errors import UsageError

    text = value.strip()
    port = int(text) if text.isdigit() else -1
    if not 0 <= port <= 65535:
        raise UsageError(
            f"{option} is {value!r}; valid: a port number 1..65535, or 0 for any free port"
        )
    if port:
        import socket

        probe = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        try:
            # As the viewer's server binds it: a port in TIME_WAIT is free, a listener is not.
            probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            probe.bind(("127.0.0.1", port))
        except OSError as e:
            raise UsageError(
                f"{option} {port}: 127.0.0.1:{port} cannot be used ({e.strerror});"
                " valid: a free port, or 0 for any free port"
            ) from None
        finally:
            probe.close()
    return port


def _log_keep(value: str | None) -> int | None:
    """--log-keep: a count of rotated parts, or ``all`` (logfiles.ALL)."""
    if value is None:
        return None
    if value == "all":
        return -1
    if value.isdigit():
        return int(value)
    from mlaunch.plan.errors import UsageError

    raise UsageError(
        f"--log-keep is {value!r}; valid: a number of rotated files (0 or more), or all"
    )


def cache_wanted(opts: Options, environ: Mapping[str, str]) -> bool:
    """Whether this run may use the plan cache: not --no-cache, not MLAUNCH_NO_CACHE=1 (any
    value but empty and 0). Decided here, before the cache's code (and pickle) is imported."""
    from mlaunch.app.quick import cache_allowed

    return opts.cache and cache_allowed(environ)
