"""``mlaunch FILE --check`` reports what a run would refuse before starting, and
``mlaunch.testing.check_launch_file`` is the same check as a test assertion (issue 32 item 5)."""

from __future__ import annotations

from pathlib import Path

import pytest
from procutil import REPO, clean_env, demo_package, run_mlaunch

from mlaunch.testing import LaunchFileCheckError, check_launch_file


def _check(path: Path, *args: str, **env: str) -> tuple[int, str]:
    done = run_mlaunch(str(path), "--check", *args, env=clean_env(**env))
    return done.returncode, done.stdout + done.stderr


def _write(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


@pytest.mark.parametrize(
    ("name", "text", "line"),
    [
        ("a.launch.yaml", 'launch:\n- arg: {name: x, default: "1"}\n- executable: {cmd: "echo $(var x"}\n', 3),
        ("a.launch.xml", '<launch>\n  <arg name="x" default="1"/>\n  <executable cmd="echo $(var x"/>\n</launch>\n', 3),
    ],
)  # fmt: skip
def test_a_file_that_does_not_load_fails_the_check(
    tmp_path: Path, name: str, text: str, line: int
) -> None:
    path = _write(tmp_path, name, text)
    code, out = _check(path)
    assert code == 1, out
    assert f"{path}:{line}" in out and "'$(var' is not closed" in out, out


@pytest.mark.parametrize("fmt", ["yaml", "xml"])
def test_an_undeclared_var_fails_the_check(tmp_path: Path, fmt: str) -> None:
    text = {
        "yaml": 'launch:\n- arg: {name: x, default: "1"}\n- executable: {cmd: "echo $(var y)"}\n',
        "xml": '<launch>\n<arg name="x" default="1"/>\n<executable cmd="echo $(var y)"/>\n</launch>\n',
    }[fmt]
    path = _write(tmp_path, f"a.launch.{fmt}", text)
    code, out = _check(path)
    assert code == 1, out
    assert f"{path}:3" in out and "launch configuration 'y' does not exist" in out, out


def test_every_error_is_reported_each_at_its_line(tmp_path: Path) -> None:
    """The check goes on after an action that fails: one check, every error."""
    prefix = demo_package(tmp_path)
    text = (
        "launch:\n"
        "- arg: {name: model}\n"  # 2: required, not given
        "- node: {pkg: demo, exec: talkr}\n"  # 3: a typo in the executable
        "- node: {pkg: dmeo, exec: talker}\n"  # 4: a typo in the package
        '- executable: {cmd: "echo $(var y)"}\n'  # 5: undeclared
        '- executable: {cmd: "echo $(var model)"}\n'  # 6: fine once model is given
        "- node: {pkg: demo, exec: talker}\n"  # 7: fine
    )
    path = _write(tmp_path, "many.launch.yaml", text)
    code, out = _check(path, AMENT_PREFIX_PATH=prefix)
    assert code == 1, out
    lines = [line for line in out.splitlines() if line.startswith(str(path))]
    assert len(lines) == 4, out
    assert f"{path}:2: required launch argument 'model' is not given" in lines[0]
    assert "pass model:=VALUE" in lines[0]
    assert f"{path}:3:" in lines[1] and "executable 'talkr' not found in package 'demo'" in lines[1]
    assert "(did you mean 'talker'?)" in lines[1]
    assert (
        f"{path}:4:" in lines[2] and "package 'dmeo' not found (did you mean 'demo'?)" in lines[2]
    )
    assert f"{path}:5:" in lines[3] and "'y' does not exist" in lines[3]
    assert "4 findings:" in out
    code, out = _check(path, "model:=m", AMENT_PREFIX_PATH=prefix)
    assert code == 1 and "model" not in out, out


def test_a_stand_in_package_with_a_misspelled_executable_names_the_executable(
    tmp_path: Path,
) -> None:
    path = _write(
        tmp_path,
        "rsp.launch.yaml",
        "launch:\n- node: {pkg: robot_state_publisher, exec: robot_state_publsher}\n",
    )
    code, out = _check(path, AMENT_PREFIX_PATH="")
    assert code == 1, out
    assert "executable 'robot_state_publsher' not found in package 'robot_state_publisher'" in out
    assert "(did you mean 'robot_state_publisher'?)" in out
    assert "package 'robot_state_publisher' not found" not in out


def test_a_missing_parameter_file_is_a_finding(tmp_path: Path) -> None:
    prefix = demo_package(tmp_path)
    path = _write(
        tmp_path,
        "p.launch.xml",
        '<launch>\n<node pkg="demo" exec="talker">\n'
        f'  <param from="{tmp_path}/nowhere.yaml"/>\n</node>\n</launch>\n',
    )
    code, out = _check(path, AMENT_PREFIX_PATH=prefix)
    assert code == 1, out
    assert f"{path}:2: Parameter file path is not a file: {tmp_path}/nowhere.yaml" in out, out


def test_the_check_starts_nothing(tmp_path: Path) -> None:
    marker = tmp_path / "started"
    path = _write(
        tmp_path,
        "t.launch.yaml",
        f'launch:\n- executable: {{cmd: "touch {marker}"}}\n- executable: {{cmd: "echo $(var y)"}}\n',
    )
    code, out = _check(path)
    assert code == 1 and "'y' does not exist" in out, out
    assert not marker.exists()


def test_a_required_argument_s_stand_in_value_causes_no_finding(tmp_path: Path) -> None:
    path = _write(
        tmp_path,
        "inc.launch.xml",
        '<launch>\n<arg name="robot"/>\n<include file="$(var robot).launch.xml"/>\n</launch>\n',
    )
    code, out = _check(path)
    assert code == 1, out
    assert out.count(str(path)) == 1 and "required launch argument 'robot'" in out, out


def test_a_good_file_passes(tmp_path: Path) -> None:
    code, out = _check(REPO / "launches/jtbot_sim.launch.yaml")
    assert code == 0, out
    assert "loads and resolves" in out


# --- the pytest helper ------------------------------------------------------------------------


@pytest.mark.parametrize(
    "name", ["jtbot_sim.launch.py", "jtbot_sim.launch.yaml", "jtbot_sim.launch.xml"]
)
def test_check_launch_file_passes_the_repository_s_files(name: str) -> None:
    check_launch_file(REPO / "launches" / name)


def test_check_launch_file_raises_with_every_finding(tmp_path: Path) -> None:
    path = _write(
        tmp_path,
        "a.launch.xml",
        '<launch>\n<arg name="m"/>\n<executable cmd="echo $(var m) $(var y)"/>\n</launch>\n',
    )
    with pytest.raises(LaunchFileCheckError) as caught:
        check_launch_file(path)
    assert isinstance(caught.value, AssertionError)
    assert len(caught.value.findings) == 2, caught.value.findings
    assert f"{path}:2: required launch argument 'm'" in caught.value.findings[0]
    assert "'y' does not exist" in caught.value.findings[1]
    with pytest.raises(LaunchFileCheckError) as caught:
        check_launch_file(path, m="x")
    assert len(caught.value.findings) == 1


def test_check_launch_file_passes_arguments(tmp_path: Path) -> None:
    path = _write(
        tmp_path,
        "a.launch.xml",
        '<launch>\n<arg name="m"/>\n<arg name="on" default="false"/>\n'
        '<executable cmd="echo $(var m)" if="$(var on)"/>\n</launch>\n',
    )
    check_launch_file(path, m="x", on=True)
    with pytest.raises(LaunchFileCheckError, match="does not exist"):
        check_launch_file(tmp_path / "no such file.launch.py")
