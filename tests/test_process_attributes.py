"""ExecuteProcess reads its keywords back as upstream's: normalized substitution lists (and
(name, value) pairs of them for the environment), and ``process_description`` is an
``Executable``; the plan made from them is the same as from the keywords as written."""

from __future__ import annotations

import os
from typing import Any

from mlaunch.frontends import xml as xml_reader
from mlaunch.launch.actions import ExecuteProcess
from mlaunch.launch.descriptions import Executable
from mlaunch.launch.launch_context import LaunchContext
from mlaunch.launch.substitution import Substitution
from mlaunch.launch.substitutions import EnvironmentVariable, perform_substitutions


def texts(subs: Any) -> str:
    assert isinstance(subs, list) and all(isinstance(s, Substitution) for s in subs), subs
    return perform_substitutions(LaunchContext(environment={"HOME": "/h"}), subs)


def test_keywords_read_back_as_substitution_lists() -> None:
    process = ExecuteProcess(
        cmd=["ls", ["-", "l"]],
        cwd="/",
        name="lister",
        additional_env={"A": EnvironmentVariable("HOME")},
        env={"ONLY": "1"},
        sigterm_timeout=2,
        sigkill_timeout="4.0",
        output="screen",
    )
    assert [texts(part) for part in process.cmd] == ["ls", "-l"]
    assert texts(process.cwd) == "/" and texts(process.name) == "lister"
    assert [(texts(k), texts(v)) for k, v in process.additional_env or ()] == [("A", "/h")]
    assert [(texts(k), texts(v)) for k, v in process.env] == [("ONLY", "1")]
    assert texts(process.sigterm_timeout) == "2" and texts(process.sigkill_timeout) == "4.0"
    assert texts(process.output) == "screen"
    assert process.emulate_tty is False and process.shell is False


def test_an_output_given_per_stream_stays_a_dict() -> None:
    streams = {"stdout": "screen", "stderr": "log"}
    assert ExecuteProcess(cmd=["ls"], output=streams).output == streams


def test_the_process_description_is_an_executable_of_the_same_process() -> None:
    process = ExecuteProcess(cmd=["ls", "-a"], name="n", additional_env={"X": "1"})
    description = process.process_description
    assert isinstance(description, Executable)
    assert [texts(list(part)) for part in description.cmd] == ["ls", "-a"]
    assert description is process.process_description  # made once
    context = LaunchContext(environment={"PATH": os.defpath})
    description.prepare(context, process)
    assert description.final_cmd == ["ls", "-a"] and description.final_env["X"] == "1"


def test_the_plan_is_the_one_the_keywords_give() -> None:
    process = ExecuteProcess(
        cmd=["ls"], cwd="/", sigterm_timeout=2, sigkill_timeout="3", output="screen"
    )
    process.prepare(LaunchContext(environment={"PATH": os.defpath}))
    details = process.process_details
    assert details is not None and details["cmd"] == ["ls"] and details["cwd"] == "/"
    spec = process.build_spec(LaunchContext(environment={"PATH": os.defpath}))
    assert (spec.sigterm_timeout, spec.sigkill_timeout, spec.output) == (2.0, 3.0, "screen")


def test_an_executable_tag_reads_back_the_same(tmp_path: Any) -> None:
    path = tmp_path / "e.launch.xml"
    path.write_text(
        '<launch><executable cmd="ls -l" cwd="/" name="my_ls" output="log"'
        ' sigkill_timeout="4.0"><env name="var" value="1"/></executable></launch>'
    )
    (process,) = xml_reader.load(str(path)).entities
    assert [texts(list(part)) for part in process.cmd] == ["ls", "-l"]
    assert texts(process.cwd) == "/" and texts(process.name) == "my_ls"
    assert texts(process.output) == "log" and texts(process.sigkill_timeout) == "4.0"
    assert [(texts(k), texts(v)) for k, v in process.additional_env] == [("var", "1")]


def test_default_timeouts_are_the_launch_configurations_every_process_shares() -> None:
    """Upstream's defaults are default arguments, made once: every process without its own
    timeouts reads back the same LaunchConfiguration (per process they cost a Substitution
    built and normalized twice each, 3,000 Python calls for 100 processes)."""
    from mlaunch.launch.substitutions import LaunchConfiguration

    one, two = ExecuteProcess(cmd=["a"]), ExecuteProcess(cmd=["b"])
    [term] = one.sigterm_timeout
    [kill] = one.sigkill_timeout
    assert isinstance(term, LaunchConfiguration) and isinstance(kill, LaunchConfiguration)
    assert two.sigterm_timeout == [term] and two.sigterm_timeout[0] is term
    assert two.sigkill_timeout[0] is kill and term is not kill
    assert one.sigterm_timeout is not two.sigterm_timeout  # each process has its own list
    context = LaunchContext()
    assert texts(one.sigterm_timeout) == "5" and texts(one.sigkill_timeout) == "5"
    context.launch_configurations["sigterm_timeout"] = "7"
    assert perform_substitutions(context, two.sigterm_timeout) == "7"


def test_plain_lists_and_tuples_normalize_as_any_iterable() -> None:
    """normalize()'s path for a plain list or tuple gives what the general one gives."""
    from mlaunch.launch.substitution import normalize

    home = EnvironmentVariable("HOME")
    for value in (["a", home, ("b", ["c"])], ("a", home, ("b", ["c"]))):
        subs = normalize(value)
        assert [type(s).__name__ for s in subs] == [
            "TextSubstitution",
            "EnvironmentVariable",
            "TextSubstitution",
            "TextSubstitution",
        ]
        assert subs[1] is home
        general = normalize(iter(value))  # an iterator takes the general path
        assert [s.describe() for s in general] == [s.describe() for s in subs]
