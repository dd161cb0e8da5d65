"""``mlaunch FILE --print --format json``: the plan as data, checked against its shipped schema.

Every launch file in launches/ (Python, YAML, XML, ROS 1, the composed one) is printed as JSON
through the real command line and validated with jsonschema; its argv equals the text --print's;
the output is stable from run to run; ``--format`` errors name the valid values; ``mlaunch test``
adds what it would check; ``--show-args --format json``. The values themselves:
test_plan_json_values.py.
"""

from __future__ import annotations

import json
import re
import shlex
from pathlib import Path

import jsonschema
import pytest
from plan_doc import (
    LAUNCH_FILES,
    LAUNCHES,
    REQUIRED_ARGUMENTS,
    env,
    launch_id,
    plan_of,
    processes,
    validate,
)
from procutil import run_mlaunch

from mlaunch.schemas import ARGUMENTS_SCHEMA, PLAN_SCHEMA, load_plan_schema, load_schema

__all__ = ["env"]  # the fixture, imported for pytest


def test_the_schema_is_a_valid_draft_2020_12_schema() -> None:
    jsonschema.Draft202012Validator.check_schema(load_plan_schema())
    assert Path(PLAN_SCHEMA).parent.name == "schemas"
    assert load_plan_schema()["properties"]["schema"]["const"] == "mlaunch-plan/1"  # type: ignore[index]


def test_every_format_is_covered() -> None:
    suffixes = {p.name.partition(".launch")[2] for p in LAUNCH_FILES}
    assert {"", ".py", ".yaml", ".xml"} <= suffixes  # ROS 1 (.launch) and the three ROS 2 ones


def test_the_composed_launch_lists_its_components(env: dict[str, str]) -> None:
    document = plan_of(str(LAUNCHES / "jtbot_composed.launch.py"), env=env)
    (load,) = [s for s in document["steps"] if s["kind"] == "load_components"]
    assert load["container"] == "/jtbot_container"
    (node,) = load["nodes"]
    assert node["plugin"] == "robot_state_publisher::RobotStatePublisher"
    assert node["full_name"] == "/robot_state_publisher"
    params = {p["name"]: p for p in node["parameters"]}
    assert params["robot_description"]["type"] == "string"
    assert params["robot_description"]["value"].lstrip().startswith("<?xml")
    assert load["origin"]["file"] == "launches/jtbot_composed.launch.py"


@pytest.mark.parametrize("path", LAUNCH_FILES, ids=launch_id)
def test_every_launch_file_validates_and_its_argv_is_what_text_print_shows(
    path: Path, env: dict[str, str]
) -> None:
    """One JSON plan per file for both (each was printed twice: 20 runs of mlaunch more)."""
    arguments = REQUIRED_ARGUMENTS.get(path.name, [])
    document = plan_of(str(path), *arguments, env=env)
    validate(document)
    assert document["schema"] == "mlaunch-plan/1"
    assert document["steps"], "an empty plan checks nothing"
    # Nothing of the run's temporary folder leaks: its files are named in plan order.
    assert "/tmp/mlaunch-" not in json.dumps(document)
    text = run_mlaunch(str(path), "--print", *arguments, env=env)
    assert text.returncode == 0, text.stderr
    lines = text.stdout.splitlines()
    shown = {
        lines[i].split()[0]: lines[i + 1].removeprefix("  argv:    ")
        for i in range(len(lines) - 1)
        if lines[i + 1].startswith("  argv:")
    }
    assert set(shown) == set(processes(document))
    # Text --print names the files a run writes <params-file N> / <run-file N>; JSON <run-temp>/N.
    temp = re.compile(r"<(?:params|run)-file \d+>")
    for label, process in processes(document).items():
        argv = process["argv"]
        shell = " ".join(argv) + "   [via /bin/sh -c]"
        expected = shell if process["shell"] else shlex.join(argv)
        names = [shlex.quote(p) for p in argv if p.startswith("<run-temp>/")]
        line = _renamed(temp, shown[label], names)
        cut = re.search(r"\.\.\. <\d+ chars>$", line)
        if cut:  # the text shortens long command lines: what it shows up to a temporary path
            head = line[: cut.start()].partition("<run-temp>/")[0]
            assert head and expected.startswith(head), label
            continue
        assert line == expected, label


def _renamed(pattern: re.Pattern[str], text: str, names: list[str]) -> str:
    """``text`` with each match of ``pattern`` replaced by the next of ``names``."""
    replacements = iter(names)
    return pattern.sub(lambda _match: next(replacements), text)


def test_output_is_stable_from_run_to_run(env: dict[str, str]) -> None:
    path = str(LAUNCHES / "examples" / "talker_listener.launch.py")
    one = run_mlaunch(path, "--print", "--format", "json", env=env)
    two = run_mlaunch(path, "--print", "--format", "json", env=env)
    assert one.returncode == 0 and one.stdout == two.stdout


def test_text_stays_the_default(env: dict[str, str]) -> None:
    path = str(LAUNCHES / "examples" / "scoping.launch.py")
    default = run_mlaunch(path, "--print", env=env)
    text = run_mlaunch(path, "--print", "--format", "text", env=env)
    assert default.returncode == 0 and default.stdout.startswith("Plan for ")
    temp = re.compile(r"/tmp/mlaunch-[^/ ]+/")
    assert temp.sub("", default.stdout) == temp.sub("", text.stdout)


@pytest.mark.parametrize("value", ["yaml", "JSON", ""])
def test_bad_format_names_the_valid_ones(value: str, env: dict[str, str]) -> None:
    path = str(LAUNCHES / "examples" / "scoping.launch.py")
    done = run_mlaunch(path, "--print", "--format", value, env=env)
    assert done.returncode == 2
    assert f"invalid choice: '{value}'" in done.stderr
    assert "'text'" in done.stderr and "'json'" in done.stderr
    assert done.stdout == ""


def test_format_json_needs_print(env: dict[str, str]) -> None:
    path = str(LAUNCHES / "examples" / "scoping.launch.py")
    done = run_mlaunch(path, "--format", "json", env=env)
    assert done.returncode == 2
    assert "--format json is for --print (-p) and --show-args (-s)" in done.stderr
    assert "process started" not in done.stdout


def test_mlaunch_test_print_adds_what_it_would_check(env: dict[str, str]) -> None:
    path = str(LAUNCHES / "examples" / "scoping.launch.py")
    plain = plan_of(path, env=env)
    assert plain["test"] is None
    done = run_mlaunch(
        "test",
        path,
        "--print",
        "--format",
        "json",
        "--expect-topic",
        "/x:5",
        "--hold",
        "1",
        env=env,
    )
    assert done.returncode == 0, done.stderr
    smoke = json.loads(done.stdout)
    validate(smoke)
    test = smoke.pop("test")
    assert {**smoke, "test": None} == plain  # the same plan as mlaunch FILE's
    assert test["hold"] == 1.0 and test["allow_exit"] == []
    checks = [(e["check"], e["target"], e["source"]) for e in test["expectations"]]
    assert checks == [
        ("process", "reporter-1", "default"),
        ("process", "simulator-2", "default"),
        ("topic", "/x", "--expect-topic '/x:5'"),
        ("shutdown", "", "default"),
    ]
    assert test["expectations"][2]["rate"] == 5.0
    # Nothing ran: no log folder, no report.
    assert not Path(env["ROS_LOG_DIR"]).exists()


def test_mlaunch_test_print_text_is_unchanged(env: dict[str, str]) -> None:
    path = str(LAUNCHES / "examples" / "scoping.launch.py")
    smoke = run_mlaunch("test", path, "--print", env=env)
    plain = run_mlaunch(path, "--print", env=env)
    temp = re.compile(r"/tmp/mlaunch-[^/ ]+/")
    assert smoke.returncode == 0 and temp.sub("", smoke.stdout) == temp.sub("", plain.stdout)


def test_every_kind_of_step_can_be_written() -> None:
    """Steps of the upper layers describe themselves (describe_data); the writer knows the rest.

    A new step kind without either would make --print --format json an internal error.
    """
    import mlaunch.launch_ros.composition
    import mlaunch.launch_ros.lifecycle_sequence
    import mlaunch.smoke.expectations  # noqa: F401  (they define Note steps)
    from mlaunch.plan import steps as plan_module
    from mlaunch.resolve.plan_json import _Writer

    known = set(_Writer(None).kinds)
    pending = list(plan_module.Step.__subclasses__())
    seen = []
    while pending:
        kind = pending.pop()
        pending.extend(kind.__subclasses__())
        if kind in (plan_module.Note, plan_module.Handoff):
            continue  # the bases of the upper layers' steps
        if not kind.__module__.startswith("mlaunch."):
            continue  # a test's own step kinds
        seen.append(kind.__name__)
        assert kind in known or callable(getattr(kind, "describe_data", None)), kind.__name__
    assert {"LoadComponents", "SequenceStep", "ExpectStep", "Spawn", "StartTimer"} <= set(seen)
    schema_kinds = load_plan_schema()["$defs"]["step"]["properties"]["kind"]["enum"]  # type: ignore[index]
    assert len(schema_kinds) == len(seen)


@pytest.mark.parametrize("path", LAUNCH_FILES, ids=launch_id)
def test_show_args_as_json(path: Path, env: dict[str, str]) -> None:
    """--show-args --format json validates and lists the arguments the text table lists."""
    given = REQUIRED_ARGUMENTS.get(path.name, [])
    done = run_mlaunch(str(path), "--show-args", "--format", "json", *given, env=env)
    assert done.returncode == 0, done.stderr
    document = json.loads(done.stdout)
    schema = load_schema(ARGUMENTS_SCHEMA)
    jsonschema.Draft202012Validator.check_schema(schema)
    errors = list(jsonschema.Draft202012Validator(schema).iter_errors(document))
    assert not errors, errors[0].message
    text = run_mlaunch(str(path), "--show-args", *given, env=env)
    rows = text.stdout.splitlines()[4:]
    names = [row.split()[0].rstrip("*") for row in rows if row.startswith("  ") and row[2] != " "]
    assert [a["name"] for a in document["arguments"]] == names
    for argument in document["arguments"]:
        value = next(
            (g.partition(":=")[2] for g in given if g.startswith(argument["name"] + ":=")), None
        )
        assert argument["value"] == value and argument["given"] == (value is not None)
