"""``mlaunch FILE --check``: what a run of the launch file would refuse before it starts anything.

The portability half (mlaunch.check.portability) reads the file against Jazzy's tables; this
half loads and resolves it as a run would, with the command line's ``name:=value`` arguments,
and starts nothing: a file that does not load (an unclosed ``$(var``), an undeclared
``$(var y)``, a required argument not given, a package or an executable that is not installed
(with did-you-mean), a parameter file that is not there. Resolving goes on after an action
that fails (``ResolveOptions.collect``), so one check names every such error, each at its
file:line. What resolving warns of (an argument the file does not declare, two nodes of the
same name, a parameter file ros2 launch would skip) is a finding too: a check is where it is
read.

A required argument that is not given is one finding; the check then goes on with a stand-in
value for it, and drops what only that stand-in value caused.
"""

from __future__ import annotations

import os
import re

from mlaunch.check.finding import Finding

TYPE_CHECKING = False  # mypy reads this as typing.TYPE_CHECKING; typing costs ~3 ms
if TYPE_CHECKING:
    from typing import TextIO

    from mlaunch.app.options import Options
    from mlaunch.plan.errors import MlaunchError

# The value a required argument that was not given takes while the check goes on.
_STAND_IN = "<required argument {name} not given>"
_WHERE = re.compile(r"^(?P<where>\S+?:\d+(?::\d+)?): (?P<message>.*)$", re.S)


def check_run(opts: Options, path: str) -> list[Finding]:
    """Every error a run of ``path`` with ``opts``'s arguments would stop at, and every
    warning resolving gives; nothing is started."""
    from mlaunch.app import pipeline
    from mlaunch.engine.lifeline import Lifeline
    from mlaunch.plan.errors import MlaunchError
    from mlaunch.resolve.resolver import ResolveOptions, resolve
    from mlaunch.ros.search import searching

    # A launch file's code and Command substitutions run while it loads: the lifeline covers them.
    with Lifeline() as life:
        try:
            path, description = pipeline.load_target(opts)
        except MlaunchError as failed:
            return [located(failed, path)]
        findings, arguments = required_arguments(opts, path, description)
        errors: list[MlaunchError] = []
        search = pipeline.package_search(opts, path)
        options = ResolveOptions(
            standins=opts.standins,
            packages=search,
            temp_dir=life.temp_dir,
            scoped_parameters=opts.scoped_parameters,
            scoped_file_locals=opts.scoped_file_locals,
            collect=errors,
        )
        if opts.use_sim_time is not None:
            from mlaunch.launch_ros.actions.set_parameter import with_use_sim_time

            description = with_use_sim_time(description, opts.use_sim_time)
        warnings: list[str] = []
        try:
            with searching(search):
                plan = resolve(
                    description,
                    path=path,
                    arguments=arguments,
                    environ=dict(os.environ),
                    options=options,
                    noninteractive=True,
                )
            warnings = plan.warnings
        except MlaunchError as stopped:  # past what collecting goes on from (too many, a cycle)
            errors.append(stopped)
    stand_ins = [_STAND_IN.format(name=name) for name in arguments if name not in opts.arguments]
    for error in errors:
        if not any(s in str(error) for s in stand_ins):
            findings.append(located(error, path))
    findings += [_warning(text, path) for text in warnings if not any(s in text for s in stand_ins)]
    return findings


def required_arguments(
    opts: Options, path: str, description: object
) -> tuple[list[Finding], dict[str, str]]:
    """(a finding per required argument the command line does not give, the arguments to
    resolve with: the command line's plus a stand-in value for each of those)."""
    from mlaunch.app.pipeline import package_search
    from mlaunch.resolve.resolver import collect_arguments
    from mlaunch.ros.search import searching

    with searching(package_search(opts, path)):
        infos = collect_arguments(
            description,  # type: ignore[arg-type]
            path=path,
            arguments=opts.arguments,
            environ=os.environ,
        )
    arguments: dict[str, str] = dict(opts.arguments)
    findings = []
    for info in infos:
        if info.default is not None or info.name in arguments or info.passed_by:
            continue
        if info.conditional:
            continue  # declared under a condition, a timer or a handler: a run may not ask
        choices = f" (one of {', '.join(map(repr, info.choices))})" if info.choices else ""
        findings.append(
            Finding(
                info.origin or path,
                f"required launch argument {info.name!r} is not given: a run refuses to start"
                f" (pass {info.name}:=VALUE{choices})",
            )
        )
        arguments[info.name] = _STAND_IN.format(name=info.name)
    return findings, arguments


def located(error: MlaunchError, path: str) -> Finding:
    """An error as a finding at its file:line (the launch file when it has none)."""
    text = f"{error.what}: {error.message}" if error.what else error.message
    return Finding(error.where or path, text)


def _warning(text: str, path: str) -> Finding:
    match = _WHERE.match(text)
    if match:
        return Finding(match["where"], match["message"])
    return Finding(path, text)


def report(opts: Options, path: str, portable: list[Finding], out: TextIO) -> int:
    """Print both halves' findings; 0 when there are none, 1 when there are."""
    findings = portable + check_run(opts, path)
    for finding in findings:
        print(finding, file=out)
    if findings:
        count = f"{len(findings)} finding{'s' if len(findings) != 1 else ''}"
        print(
            f"{count}: a run would refuse these, or ros2 launch (Jazzy) would reject or read"
            " them differently",
            file=out,
        )
        return 1
    print(
        f"{path}: loads and resolves, and nothing ros2 launch (Jazzy) would reject or read"
        " differently",
        file=out,
    )
    return 0
