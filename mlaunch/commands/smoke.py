"""``mlaunch test FILE``: a CI smoke run of a launch file (the options: mlaunch.smoke.settings).

It starts the launch exactly as ``mlaunch FILE`` would (the same pipeline, the same parts
attached), plus the checks: the expectations (mlaunch.smoke.expectations) are watched
(mlaunch.smoke.watch) until the system is ready, held, then the launch is shut down and a
report (mlaunch.smoke.report) says what was expected and seen.
"""

from __future__ import annotations

import os
import re
import sys
from collections.abc import Sequence
from typing import TYPE_CHECKING

from mlaunch.launch_ros.composition import LoadComponents
from mlaunch.plan.errors import EXIT_FAILURE, EXIT_OK, UsageError
from mlaunch.smoke import junit
from mlaunch.smoke.expectations import (
    Expect,
    Expectation,
    ExpectStep,
    _CollectConfigurations,
    _true,
    expectation_data,
    parse_spec,
    parse_target,
)
from mlaunch.smoke.report import Report
from mlaunch.smoke.settings import Settings, parse_settings, split_arguments
from mlaunch.smoke.watch import SmokeRun

if TYPE_CHECKING:
    from mlaunch.app.options import Options
    from mlaunch.engine.lifeline import Lifeline
    from mlaunch.parts.ros1_native import NativeRun
    from mlaunch.plan.steps import Plan, ProcessSpec
    from mlaunch.resolve.resolver import LabelCounter, ResolveOptions
    from mlaunch.smoke.artifacts import Bundle
    from mlaunch.smoke.recorder import Recorder


def command(args: Sequence[str]) -> int:
    """``mlaunch test``'s work; errors go up to mlaunch.cli.main."""
    from mlaunch.app import pipeline
    from mlaunch.app.options import parse_options

    args = list(args)
    many = _many(args)  # several files (launch_testing files among them), each its own run
    if many is not None:
        from mlaunch.commands.smoke_many import run_many

        return run_many(*many)
    from mlaunch.launch_testing.launch_test import is_launch_test_file

    if any(is_launch_test_file(a) for a in args if not a.startswith("-")):
        # A launch_testing file (it defines generate_test_description): launch_test runs it.
        from mlaunch.launch_testing.launch_test import main as launch_test_main

        return launch_test_main(args, prog="mlaunch test")
    as_json = _take_json(args)
    mine, rest = split_arguments(args)
    try:
        settings = parse_settings(mine)
        opts = parse_options(rest) if rest else None
    except SystemExit as e:  # argparse: --help (0) or a usage error (2), already printed
        return int(e.code or 0)
    if opts is None:
        raise UsageError("a launch file is needed: mlaunch test FILE [name:=value ...]")
    if opts.print_plan and opts.format == "json":
        return print_plan(opts, settings)
    if opts.show_args or opts.print_plan:
        from mlaunch.app.parts import standard_parts

        return pipeline.launch(opts, standard_parts(opts))
    if settings.junit:
        junit.check_target(settings.junit)  # found now, not after the whole test ran
    settings.json = as_json
    return run(opts, settings)


def _take_json(args: list[str]) -> bool:
    """Take ``--format json`` out of ``args`` when it is for the verdict (not --print's or
    --show-args's): the verdict is then JSON on stdout, and what the run says goes to stderr."""
    views = {"-p", "--print", "--print-description", "-s", "--show-args", "--show-arguments"}
    if views & set(args):
        return False
    for i, arg in enumerate(args):
        if arg == "--format" and i + 1 < len(args) and args[i + 1] == "json":
            del args[i : i + 2]
            return True
        if arg == "--format=json":
            del args[i]
            return True
    return False


def _many(
    args: list[str],
) -> tuple[list[str], list[str], int, str | None, int, str | None] | None:
    """``mlaunch test FILE... [-j N]``: (files, the arguments every run gets, N, --junit), or
    None for one launch. Several files are meant when -j is given, or when every positional
    word names a launch file that exists (``PKG FILE`` names a package first)."""
    from mlaunch.app.options import VALUE_OPTIONS
    from mlaunch.commands.smoke_many import parse_jobs
    from mlaunch.smoke.settings import VALUE_FLAGS

    jobs: int | None = None
    repeat = 1
    junit_path: str | None = None
    evidence: str | None = None
    files: list[str] = []
    shared: list[str] = []
    words = iter(args)
    for arg in words:
        if arg in ("-j", "--jobs"):
            jobs = parse_jobs(next(words, ""))
        elif arg.startswith("--jobs="):
            jobs = parse_jobs(arg.split("=", 1)[1])
        elif arg.startswith("-j") and arg[2:].isdigit():
            jobs = parse_jobs(arg[2:])
        elif arg == "--repeat" or arg.startswith("--repeat="):
            value = arg.split("=", 1)[1] if "=" in arg else next(words, "")
            repeat = int(value) if value.isdigit() else 0
            if repeat < 1:
                raise UsageError(f"--repeat {value!r}: expected a number of runs >= 1")
        elif arg == "--artifacts" or arg.startswith("--artifacts="):
            evidence = arg.split("=", 1)[1] if "=" in arg else next(words, "")
        elif arg in ("--junit", "--junit-xml"):
            junit_path = next(words, None)
        elif arg.startswith(("--junit=", "--junit-xml=")):
            junit_path = arg.split("=", 1)[1]
        elif arg in VALUE_FLAGS or arg in VALUE_OPTIONS:
            shared += [arg, next(words, "")]
        elif arg.startswith("-") or ":=" in arg:
            shared.append(arg)
        else:
            files.append(arg)
    several = len(files) > 1 and all(os.path.isfile(f) for f in files)
    if jobs is None and not several and repeat == 1:
        return None
    if not files:
        raise UsageError("mlaunch test FILE... -j N: name the launch files to test")
    return files, shared, jobs or 1, junit_path, repeat, evidence


# --- running --------------------------------------------------------------------------------------


def run(opts: Options, settings: Settings) -> int:
    """Load, resolve, supervise with the smoke checks attached; report; the exit status."""
    from mlaunch.engine.lifeline import Lifeline
    from mlaunch.engine.logfiles import make_run_log_dir
    from mlaunch.ros import domain

    if settings.json:  # stdout is the verdict's: what the run says goes to stderr meanwhile
        sys.stdout.flush()
        settings.stdout = os.dup(1)
        os.dup2(2, 1)
    # A domain of its own (unless the user chose one): runs at the same time never meet.
    claimed = domain.isolate(os.environ)
    try:
        with Lifeline() as life:  # signals, guard and marker from the first line of the launch on
            log_dir = make_run_log_dir(os.environ)
            path, plan, options, labels, expectations, native = prepare(
                opts, settings, life, log_dir
            )
            checked = (path, expectations, native)
            isolation = (domain.describe(os.environ, claimed), os.environ.get("ROS_DOMAIN_ID", ""))
            return supervise(
                opts, settings, plan, options, labels, log_dir, checked, life, isolation
            )
    finally:
        if claimed is not None:
            claimed.release()
        _stdout_back(settings)


def recorded_topics(expectations: list[Expectation], settings: Settings) -> list[str]:
    """The topics whose last seconds the evidence keeps: those the checks name, --record's."""
    topics = list(settings.record)
    for e in expectations:
        if e.kind in ("topic", "clock"):
            topics.append(e.target)
        elif e.kind == "tf":
            topics += ["/tf", "/tf_static"]
    return list(dict.fromkeys(topics))


def write_evidence(
    folder: str,
    opts: Options,
    plan: Plan,
    path: str,
    report: Report,
    smoke: SmokeRun,
    log_dir: str,
    recorders: list[Recorder],
) -> Bundle:
    """The failure's evidence (mlaunch.smoke.artifacts); what cannot be written is said."""
    from mlaunch.resolve.plan_json import plan_json
    from mlaunch.smoke import artifacts

    return artifacts.write(
        folder,
        verdict=report.data(),
        plan_text=plan_json(plan, path, opts.arguments),
        processes=smoke.supervisor.processes,
        rings=smoke.rings,
        log_dir=log_dir,
        recorder=recorders[0] if recorders else None,
    )


def _stdout_back(settings: Settings) -> None:
    if settings.stdout is not None:
        os.dup2(settings.stdout, 1)
        os.close(settings.stdout)
        settings.stdout = None


def print_plan(opts: Options, settings: Settings) -> int:
    """``mlaunch test FILE --print --format json``: the plan, plus what the run would check."""
    from mlaunch.engine.lifeline import Lifeline, write_stdout
    from mlaunch.resolve.plan_json import plan_json

    with Lifeline() as life:  # a launch file's code and Command substitutions may run
        path, plan, _options, _labels, expectations, _ = prepare(opts, settings, life, "")
        test = {
            "timeout": settings.timeout,
            "hold": settings.hold,
            "allow_exit": list(settings.allow_exit),
            "expectations": [expectation_data(e) for e in expectations],
        }
        write_stdout(plan_json(plan, path, opts.arguments, test=test))
    return EXIT_OK


def prepare(
    opts: Options, settings: Settings, life: Lifeline, log_dir: str
) -> tuple[str, Plan, ResolveOptions, LabelCounter, list[Expectation], NativeRun | None]:
    """Load and resolve as ``mlaunch FILE`` does, with the launch configurations collected;
    (path, plan, resolve options, labels, the expectations of the run, the native ROS 1 run
    it is, if it is one)."""
    from mlaunch.app import pipeline
    from mlaunch.launch.launch_description import LaunchDescription

    path, description = pipeline.load_target(opts, temp_dir=life.temp_dir)
    collector = _CollectConfigurations()
    plan, options, labels = pipeline.resolve_for_run(
        opts,
        path,
        LaunchDescription([description, collector]),
        temp_dir=life.temp_dir,
        log_dir=log_dir,
    )
    # use_sim_time:=true is an ordinary launch argument; a file that declares it is
    # expected to run on simulated time, as --use-sim-time is.
    native = _native_ros1(description)
    if native is not None:
        expectations = ros1_expectations(plan, settings, collector, native)
        return path, plan, options, labels, expectations, native
    sim_time = bool(opts.use_sim_time) or _true(opts.arguments.get("use_sim_time", "false"))
    expectations = build_expectations(plan, settings, collector, sim_time)
    return path, plan, options, labels, expectations, None


def _native_ros1(description: object) -> NativeRun | None:
    """The native ROS 1 run ``description`` is, if it is one. Only the pipeline imports
    ros1_native, and only for a roslaunch file: any other run does not pay for it."""
    module = sys.modules.get("mlaunch.parts.ros1_native")
    return None if module is None else module.native_run(description)


# What a native ROS 1 run can check: its master knows nodes and services; a topic's messages
# are counted by a rospy helper (mlaunch.parts.ros1_graph).
ROS1_KINDS = ("process", "output", "node", "service", "topic")


def ros1_expectations(
    plan: Plan, settings: Settings, collector: _CollectConfigurations, native: NativeRun
) -> list[Expectation]:
    """A native ROS 1 run's checks: its processes, every node it starts registered with the
    master (the nodes start once the parameter server is loaded: they are not in the plan),
    then the launch file's and the command line's."""
    out: dict[tuple[str, str], Expectation] = {}
    for spec in plan.processes():
        out[("process", spec.label)] = Expectation("process", spec.label, labels=[spec.label])
    for node in native.nodes:
        out.setdefault(("node", node.full_name), Expectation("node", node.full_name))
        out[("node", node.full_name)].labels = [node.name]
    explicit = [s.expectation for s in plan.steps if isinstance(s, ExpectStep) and s.expectation]
    for expectation in [*explicit, *collector.found, *settings.expectations]:
        if expectation.kind not in ROS1_KINDS:
            raise UsageError(
                f"{expectation.kind} expectation ({expectation.origin}): a native ROS 1 run"
                f" checks {', '.join(ROS1_KINDS)} (its master is asked which nodes and services"
                " are registered, topics' messages are counted; /clock and lifecycle states"
                " are not read)"
            )
        out[expectation.key()] = expectation
        if expectation.kind == "output":
            _involve(expectation, plan.processes())
    found = list(out.values())
    found.append(Expectation("shutdown", "", status="pending", seen="the launch was not stopped"))
    return found


def build_expectations(
    plan: Plan, settings: Settings, collector: _CollectConfigurations, use_sim_time: bool
) -> list[Expectation]:
    """Defaults from the plan, then the launch file's, then the command line's (later wins)."""
    specs = plan.processes()
    explicit = [s.expectation for s in plan.steps if isinstance(s, ExpectStep) and s.expectation]
    explicit += collector.found + settings.expectations
    out: dict[tuple[str, str], Expectation] = {}
    for spec in specs:
        out[("process", spec.label)] = Expectation("process", spec.label, labels=[spec.label])
    for spec in specs:
        fqn = spec.node.fully_qualified_name if spec.node is not None else None
        if spec.node is None or fqn is None:
            continue
        out.setdefault(("node", fqn), Expectation("node", fqn))
        if spec.node.lifecycle:
            out.setdefault(("lifecycle", fqn), Expectation("lifecycle", fqn))
    components: dict[str, str] = {}  # composable node -> its container (LoadComponents steps)
    for step in plan.steps:
        if not isinstance(step, LoadComponents):
            continue
        for name in step.component_names():
            components[name] = step.target
            out.setdefault(("node", name), Expectation("node", name))
    if use_sim_time or collector.use_sim_time or any(_sim_time_argv(s.argv) for s in specs):
        out[("clock", "/clock")] = Expectation("clock", "/clock")
    for expectation in explicit:
        out[expectation.key()] = expectation
    for expectation in out.values():
        _involve(expectation, specs)
        if expectation.kind == "node" and expectation.target in components:
            container = components[expectation.target]
            expectation.labels = [
                s.label for s in specs if s.node and s.node.fully_qualified_name == container
            ]
    found = list(out.values())
    found.append(Expectation("shutdown", "", status="pending", seen="the launch was not stopped"))
    return found


def _sim_time_argv(argv: Sequence[str]) -> bool:
    return any(a.lower() in ("use_sim_time:=true", "use_sim_time:=1") for a in argv)


def _involve(expectation: Expectation, specs: list[ProcessSpec]) -> None:
    """Which processes' output explains this expectation; compile an output regex."""
    if expectation.kind in ("node", "lifecycle"):
        expectation.labels = [
            s.label
            for s in specs
            if s.node is not None and s.node.fully_qualified_name == expectation.target
        ]
    elif expectation.kind in ("output", "forbid"):
        names = {s.label for s in specs} | {s.base_name for s in specs}
        head, sep, tail = expectation.target.partition(":")
        if sep and head in names:
            expectation.process, expectation.target = head, tail
        if expectation.process:
            expectation.labels = [
                s.label for s in specs if expectation.process in (s.label, s.base_name)
            ]
        try:
            expectation.regex = re.compile(expectation.target)
        except re.error as e:
            raise UsageError(
                f"{expectation.kind} expectation ({expectation.origin}): {expectation.target!r}"
                " is not a"
                f" regular expression: {e}"
            )


def supervise(
    opts: Options,
    settings: Settings,
    plan: Plan,
    options: ResolveOptions,
    labels: LabelCounter,
    log_dir: str,
    checked: tuple[str, list[Expectation], NativeRun | None],
    life: Lifeline,
    isolation: tuple[str, str] = ("", ""),
) -> int:
    """Run the plan as ``mlaunch FILE`` would (the same parts attached), plus the smoke checks.

    The checks attach last, so lifecycle driving, if the plan needs it, already exists and its
    ROS graph is shared.
    """
    from mlaunch.app import pipeline
    from mlaunch.app.parts import PartMaker, Run, standard_parts

    runs: list[SmokeRun] = []
    recorders: list[Recorder] = []

    path, expectations, native = checked
    master = None
    if native is not None:  # its master is the graph the checks look at
        from mlaunch.parts.ros1_graph import SharedMaster

        master = SharedMaster(native.master_uri)

    topics = recorded_topics(expectations, settings)
    if topics and native is None and settings.record_seconds > 0:
        from mlaunch.smoke.recorder import Recorder

        recorders.append(Recorder(topics, settings.record_seconds))

    def smoke_checks(run: Run) -> SmokeRun:
        smoke = SmokeRun(
            run.supervisor,
            expectations,
            settings,
            lifecycle=run.lifecycle,
            graph=master,
            recorder=recorders[0] if recorders else None,
        )
        runs.append(smoke)
        return smoke

    # Without its checks the run proves nothing: if they fail, the run ends (exit status 70).
    checks = PartMaker("the smoke checks", smoke_checks, essential=True)
    parts = [*standard_parts(opts), checks]

    code = pipeline.supervise(opts, plan, options, labels, log_dir, life, parts, path=path)
    if not runs:
        return code
    smoke = runs[0]
    smoke.conclude()
    words, domain_id = isolation if native is None else ("", "")  # ROS 1 has no domains
    notes = [f"ROS domain {words}"] if words else []
    properties = {"ros_domain_id": domain_id} if domain_id else {}
    if smoke.others:
        shown = ", ".join(sorted(smoke.others)[:3])
        notes.append(
            f"warning: another test shares this ROS domain (its graph node {shown} was seen):"
            " its nodes and topics may have been taken for this launch's"
        )
        properties["other_tests_seen"] = str(len(smoke.others))
    report = Report(
        path,
        expectations,
        smoke.rings,
        smoke.elapsed(),
        smoke.window(),
        properties=properties,
        notes=notes,
    )
    failed = not report.passed or code != EXIT_OK
    if settings.artifacts or failed:
        folder = settings.artifacts or os.path.join(log_dir, "artifacts")
        bundle = write_evidence(folder, opts, plan, path, report, smoke, log_dir, recorders)
        report.notes.append(bundle.line())
    if settings.json:
        sys.stderr.write(report.table())
        sys.stderr.flush()
        _stdout_back(settings)
        sys.stdout.write(report.json())
    else:
        sys.stdout.write(report.table())
    sys.stdout.flush()
    if settings.junit:
        report.write_junit(settings.junit)
    if code >= 128:
        return code  # interrupted: say so, whatever was seen
    return EXIT_OK if report.passed else EXIT_FAILURE


__all__ = [
    "Expect",
    "Expectation",
    "Settings",
    "_CollectConfigurations",
    "build_expectations",
    "junit",
    "parse_settings",
    "parse_spec",
    "parse_target",
    "run",
    "split_arguments",
]
