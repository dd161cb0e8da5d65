"""Hostile or broken launch files and streams: one located line or a clear status, never a
RecursionError, an internal error or gigabytes (issue 27, items 8-10)."""

from __future__ import annotations

import subprocess
import time
from pathlib import Path

import pytest
from procutil import clean_env, mlaunch, run_mlaunch

from mlaunch.launch.substitution import SUBSTITUTION_DEPTH_LIMIT
from mlaunch.plan.yamldata import ALIAS_LIMIT


@pytest.fixture
def env(tmp_path: Path) -> dict[str, str]:
    return clean_env(ROS_LOG_DIR=str(tmp_path / "logs"))


def fails(path: Path, env: dict[str, str]) -> str:
    """``mlaunch path --print``: exit 2, one ``mlaunch: error:`` line located in ``path``."""
    done = run_mlaunch(str(path), "--print", env=env, timeout=60)
    assert done.returncode == 2, done.stdout[-2000:] + done.stderr[-2000:]
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"mlaunch: error: {path}:"), done.stderr
    assert len(lines[0]) < 600, lines[0]  # one readable line, not the 60 KB attribute
    return lines[0]


# --- item 8: YAML alias bombs ----------------------------------------------------------------


def alias_bomb(levels: int) -> str:
    """Each level a list holding two aliases of the level below: 2**levels leaves."""
    lines = ["launch:", "- group:", "    children: &l0", "    - executable: {cmd: 'true', name: t}"]
    for i in range(1, levels + 1):
        lines += [
            "- group:",
            f"    children: &l{i}",
            f"    - group: {{children: *l{i - 1}}}",
            f"    - group: {{children: *l{i - 1}}}",
        ]
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize("levels", [16, 24])
def test_a_yaml_alias_bomb_fails_fast_with_a_located_line(
    tmp_path: Path, env: dict[str, str], levels: int
) -> None:
    path = tmp_path / "bomb.launch.yaml"
    path.write_text(alias_bomb(levels))
    assert len(path.read_text().splitlines()) <= 100
    start = time.monotonic()
    error = fails(path, env)  # before: 16 levels planned 131,071 processes, 24 took 6.5 GB
    assert time.monotonic() - start < 10
    assert f"expand this list by more than {ALIAS_LIMIT:,} nodes" in error


def test_aliases_a_real_file_uses_still_work(tmp_path: Path, env: dict[str, str]) -> None:
    path = tmp_path / "reuse.launch.yaml"
    path.write_text(alias_bomb(4))  # 1 + 2 + 4 + 8 + 16 processes, through aliases
    done = run_mlaunch(str(path), "--print", env=env)
    assert done.returncode == 0, done.stderr
    assert "31 process(es) at start" in done.stdout


def test_an_alias_inside_what_it_names_is_a_located_line(
    tmp_path: Path, env: dict[str, str]
) -> None:
    path = tmp_path / "cycle.launch.yaml"
    path.write_text("launch:\n- group: &g\n    children:\n    - group: *g\n")
    assert "a YAML alias repeats the map it is in" in fails(path, env)


# --- item 9: substitutions nested thousands deep ----------------------------------------------


def nested_env(depth: int) -> str:
    text = "A"
    for _ in range(depth):
        text = f"$(env X {text})"
    return text


NESTED_SUBST = {
    "xml": (".launch.xml", lambda d: f'<launch>\n<executable cmd="echo {nested_env(d)}"/>\n</launch>\n'),
    "yaml": (".launch.yaml", lambda d: f'launch:\n- executable: {{cmd: "echo {nested_env(d)}"}}\n'),
    "python": (
        ".launch.py",
        lambda d: "from launch import LaunchDescription\n"
        "from launch.actions import ExecuteProcess\n"
        "from launch.substitutions import EnvironmentVariable\n"
        "def generate_launch_description():\n"
        "    s = 'A'\n"
        f"    for _ in range({d}):\n"
        "        s = EnvironmentVariable('X', default_value=[s])\n"
        "    return LaunchDescription([ExecuteProcess(cmd=['echo', s])])\n",
    ),
}  # fmt: skip


@pytest.mark.parametrize("fmt", sorted(NESTED_SUBST))
def test_substitutions_nested_thousands_deep_are_a_located_line(
    tmp_path: Path, env: dict[str, str], fmt: str
) -> None:
    suffix, make = NESTED_SUBST[fmt]
    path = tmp_path / f"deep{suffix}"
    path.write_text(make(20_000 if fmt == "python" else 7_000))
    error = fails(path, env)
    assert f"substitutions nest deeper than {SUBSTITUTION_DEPTH_LIMIT} levels" in error
    assert f"{path}:{8 if fmt == 'python' else 2}" in error


@pytest.mark.parametrize("fmt", sorted(NESTED_SUBST))
def test_substitutions_nested_to_the_limit_resolve(
    tmp_path: Path, env: dict[str, str], fmt: str
) -> None:
    suffix, make = NESTED_SUBST[fmt]
    path = tmp_path / f"ok{suffix}"
    path.write_text(make(SUBSTITUTION_DEPTH_LIMIT - 1))
    done = run_mlaunch(str(path), "--print", env=clean_env(X="x"))
    assert done.returncode == 0, done.stderr
    assert "argv:    echo x\n" in done.stdout


# --- item 10: output that cannot be written, a launch file that closes stdout, encodings -----

OK = """from launch import LaunchDescription
from launch.actions import ExecuteProcess
{extra}
def generate_launch_description():
    return LaunchDescription([ExecuteProcess(cmd=["echo", "hi"], name="t")])
"""


@pytest.mark.parametrize("args", [["--print"], ["--show-args"], ["--check"]])
def test_a_stdout_that_cannot_be_written_is_one_line_and_status_74(
    tmp_path: Path, env: dict[str, str], args: list[str]
) -> None:
    path = tmp_path / "ok.launch.py"
    path.write_text(OK.format(extra=""))
    with open("/dev/full", "w") as full:
        done = subprocess.run(
            mlaunch(str(path), *args), stdout=full, stderr=subprocess.PIPE, text=True, env=env,
            timeout=30,
        )  # fmt: skip
    assert done.returncode == 74, done.stderr
    assert done.stderr == (
        "mlaunch: error: cannot write to standard output: No space left on device\n"
    )


@pytest.mark.parametrize("args", [["--print"], []])
def test_a_launch_file_that_closes_stdout_is_handled(
    tmp_path: Path, env: dict[str, str], args: list[str]
) -> None:
    path = tmp_path / "closes.launch.py"
    path.write_text(OK.format(extra="import sys\nsys.stdout.close()\n"))
    done = run_mlaunch(str(path), *args, env=env)
    assert done.returncode == 0, done.stderr
    assert "closed sys.stdout; mlaunch opened it again" in done.stderr
    assert "internal error" not in done.stderr
    assert ("argv:    echo hi" if args else "process has finished cleanly") in done.stdout


def test_a_python_file_with_a_non_utf8_comment_is_rejected(
    tmp_path: Path, env: dict[str, str]
) -> None:
    path = tmp_path / "latin.launch.py"
    path.write_bytes(OK.format(extra="# caf\xe9").encode("latin-1"))
    error = fails(path, env)
    assert f"{path}:3:6: the file is not UTF-8 text: byte 0xE9" in error
