"""The command line: argv -> Options -> load -> resolve -> run. The only place errors are printed.

Exit status (the table is mlaunch.plan.errors'):
  0    every process ended and nothing required failed (or a Shutdown action ended the launch)
  1    a required process (on_exit=Shutdown / required=True) exited with a failure
  2    bad command line or launch file: missing file, syntax error, bad argument, failed
       substitution, missing package or executable (one line on stderr, no traceback)
  70   an internal error of mlaunch (a bug: --debug shows the traceback)
  74   standard output cannot be written (a full disk, /dev/full): one line on stderr
  128+N  mlaunch was stopped by signal N: 130 for Ctrl-C (SIGINT), 143 SIGTERM, 129 SIGHUP
"""

from __future__ import annotations

import os
import sys

# Nothing else at first: the quick start (mlaunch.app.quick) starts a repeated launch's first
# processes before the rest of mlaunch is imported.
TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from collections.abc import Sequence

    from mlaunch.app.options import Options
    from mlaunch.app.parts import Run
    from mlaunch.app.quick import Prestart
    from mlaunch.engine.part import Part


def main(argv: Sequence[str] | None = None, quick: Prestart | None = None) -> int:
    """``mlaunch ...`` and its subcommands: the one place errors are caught and printed.

    ``quick``: the quick start of ``program`` (its children adopted by the run)."""
    args = list(sys.argv[1:] if argv is None else argv)
    debug = "--debug" in args or "-d" in args
    from mlaunch import compat
    from mlaunch.commands import subcommands

    compat.install()  # launch files import the ROS 2 names (launch, launch_ros ...)
    try:
        sub = subcommands().get(args[0]) if args and not os.path.isfile(args[0]) else None
        if sub is not None:  # each parses its own options and runs through mlaunch.app
            return sub.main(args[1:])
        return run_cli(args, quick)
    except BrokenPipeError:
        from mlaunch.engine.lifeline import stdout_gone

        return stdout_gone()
    except OSError as e:
        return report_error(_output_error(e) if _is_write_error(e) else e, debug)
    except (Exception, KeyboardInterrupt) as e:  # KeyboardInterrupt: Ctrl-C, lifeline.Stopped
        return report_error(e, debug)


def report_error(error: BaseException, debug: bool) -> int:
    """The error printed once (see mlaunch.plan.errors.report); its exit status."""
    from mlaunch.plan.errors import report

    return report(error, debug=debug)


def run_cli(argv: Sequence[str], quick: Prestart | None = None) -> int:
    """``mlaunch FILE ...``: the pipeline with what every run attaches (or ``--check``)."""
    from mlaunch.app import pipeline
    from mlaunch.app.options import parse_options
    from mlaunch.app.parts import PartMaker, standard_parts

    opts = parse_options(argv)
    if opts.check:
        return check_target(opts)
    parts = standard_parts(opts)
    # Before the control socket opens: it answers wait-ready through it.
    parts.insert(0, PartMaker("the readiness checks", _readiness))
    if quick is None:  # the plan's first processes start before the supervisor is made
        from mlaunch.app.quick import Prestart

        quick = Prestart()
    return pipeline.launch(opts, parts, quick)


def _readiness(run: Run) -> Part:
    """Readiness for systemd and ``ctl wait-ready`` (imported only when the run attaches it)."""
    from mlaunch.commands.readiness import attach

    return attach(run)


def check_target(opts: Options) -> int:
    """``--check``: what a run would refuse and what Jazzy would read otherwise; nothing starts."""
    from mlaunch.app.pipeline import find_launch_file, package_search
    from mlaunch.check import loading, portability
    from mlaunch.ros.search import searching

    with searching(package_search(opts, None)):
        path = find_launch_file(opts)
        portable = portability.check(path)
    return loading.report(opts, path, portable, sys.stdout)


def program() -> None:
    """The ``mlaunch`` program: main(), then exit without interpreter teardown.

    By the time main() returns, the printer is closed, the guard reaped and the temp dir gone;
    only stdio buffers remain, so flushing them and calling os._exit skips ~8 ms of teardown
    between the last child's death and mlaunch's. Tests call main() instead.
    """
    from mlaunch.engine.lifeline import ensure_std_streams

    ensure_std_streams()  # a closed stdout (mlaunch FILE >&-) must not lend its number to a file
    if "_ARGCOMPLETE" in os.environ:  # the shell asks for completions: answered, then exit
        from mlaunch.cli.completion import complete

        complete()
    quick = None
    try:
        from mlaunch.app.quick import prestart

        quick = prestart(sys.argv[1:], os.environ)
        code = main(quick=quick)
    except SystemExit as e:  # argparse's usage errors and --help
        code = e.code if isinstance(e.code, int) else (0 if e.code is None else 2)
    except (Exception, KeyboardInterrupt) as e:  # the quick start's (a signal while it starts)
        code = report_error(e, "--debug" in sys.argv or "-d" in sys.argv)
    finally:
        if quick is not None:
            quick.close()  # what the run did not adopt (it ended before): none, normally
    code = flush_std_streams(code)
    os._exit(code)


def flush_std_streams(code: int) -> int:
    """Flush what print() left buffered; a stdout that cannot take it makes a 0 status 74."""
    from mlaunch.plan.errors import EXIT_OUTPUT

    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except BrokenPipeError:  # a closed pipe (mlaunch ... | head)
            pass
        except OSError as e:
            if stream is sys.stdout and code == 0:
                report_error(_output_error(e), False)
                code = EXIT_OUTPUT
        except ValueError:  # closed
            pass
    return code


def _is_write_error(error: OSError) -> bool:
    """A write that the disk or device refused (no file named: print() to a full stdout)."""
    import errno

    codes = (errno.ENOSPC, errno.EDQUOT, errno.EFBIG, errno.EIO)
    return error.errno in codes and error.filename is None


def _output_error(error: OSError) -> Exception:
    from mlaunch.plan.errors import OutputError

    return OutputError(f"cannot write to standard output: {error.strerror or error}")


if __name__ == "__main__":
    program()
