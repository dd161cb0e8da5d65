"""``mlaunch export`` writes only into a folder of the user's own that nobody else can write,
never through a link, with explicit modes: another user's empty folder let them edit the units
before root installed them, and ``--force`` (as the error advises) followed their symlinks and
wrote unit text over root's files; under umask 000 the units were 0666 in a 0777 folder.

The other user is ``nobody`` (setpriv), which only root can play.
"""

from __future__ import annotations

import os
import stat
import subprocess
from collections.abc import Iterator
from pathlib import Path

import pytest
from procutil import REPO, clean_env, mlaunch

PREFIX = REPO / "launches" / "examples" / "prefix"
LAUNCH = """
from launch import LaunchDescription
from launch.actions import ExecuteProcess

def generate_launch_description():
    return LaunchDescription([ExecuteProcess(cmd=["sleep", "1000"], name="worker")])
"""
as_root = pytest.mark.skipif(os.geteuid() != 0, reason="playing another user (nobody) needs root")


def _as_nobody(*argv: str) -> None:
    subprocess.run(
        ["setpriv", "--reuid=65534", "--regid=65534", "--clear-groups", *argv],
        check=True,
        timeout=30,
    )


def export(tmp_path: Path, out: Path, *extra: str, umask: int | None = None) -> tuple[int, str]:
    launch = tmp_path / "demo.launch.py"
    launch.write_text(LAUNCH)
    done = subprocess.run(
        [*mlaunch("export", str(launch), "--to", "systemd", str(out), *extra)],
        capture_output=True,
        text=True,
        env=clean_env(AMENT_PREFIX_PATH=str(PREFIX)),
        timeout=120,
        preexec_fn=None if umask is None else (lambda: os.umask(umask)),
    )
    return done.returncode, done.stdout + done.stderr


@pytest.fixture
def shared(tmp_path: Path) -> Iterator[Path]:
    """A folder every user can reach (tmp_path's parents are root's 0700)."""
    base = Path("/tmp") / f"mlaunch-export-{os.getpid()}-{tmp_path.name}"
    base.mkdir(mode=0o1777)
    base.chmod(0o1777)
    yield base
    subprocess.run(["rm", "-rf", str(base)], check=False)


@as_root
def test_another_users_empty_folder_is_refused(tmp_path: Path, shared: Path) -> None:
    theirs = shared / "units"
    _as_nobody("mkdir", "-m", "755", str(theirs))
    code, out = export(tmp_path, theirs)
    assert code == 2, out
    assert f"'{theirs}' belongs to uid 65534 (nobody), not to you" in out
    assert list(theirs.iterdir()) == []


@as_root
def test_force_never_writes_through_a_planted_symlink(tmp_path: Path, shared: Path) -> None:
    victim = tmp_path / "victim.conf"
    victim.write_text("root's own file\n")
    theirs = shared / "units"
    _as_nobody("mkdir", "-m", "755", str(theirs))
    _as_nobody("ln", "-s", str(victim), str(theirs / "demo-worker-1.service"))
    code, out = export(tmp_path, theirs, "--force")
    assert code == 2, out
    assert "belongs to uid 65534 (nobody)" in out
    assert victim.read_text() == "root's own file\n"
    # In a folder of root's own, what stands at a unit's name is replaced, never followed.
    own = tmp_path / "own"
    own.mkdir()
    (own / "demo-worker-1.service").symlink_to(victim)
    code, out = export(tmp_path, own, "--force")
    assert code == 0, out
    assert victim.read_text() == "root's own file\n"
    assert stat.S_ISREG((own / "demo-worker-1.service").lstat().st_mode)


def test_a_folder_others_can_write_is_refused(tmp_path: Path) -> None:
    open_to_all = tmp_path / "units"
    open_to_all.mkdir()
    open_to_all.chmod(0o777)
    code, out = export(tmp_path, open_to_all)
    assert code == 2, out
    assert "has mode 777: others can write into it" in out
    assert list(open_to_all.iterdir()) == []


def test_a_folder_inside_one_others_can_write_is_refused(tmp_path: Path) -> None:
    """Whoever can write the folder above can rename the units' folder and put their own."""
    above = tmp_path / "open"
    above.mkdir()
    above.chmod(0o777)
    code, out = export(tmp_path, above / "units")
    assert code == 2, out
    assert f"is in a folder others could change: {above} has mode 777" in out
    assert list(above.iterdir()) == []


def test_a_symlinked_folder_is_not_followed(tmp_path: Path) -> None:
    real = tmp_path / "real"
    real.mkdir()
    link = tmp_path / "link"
    link.symlink_to(real)
    code, out = export(tmp_path, link)
    assert code == 2, out
    assert "is a symlink; name the folder it points to" in out
    assert list(real.iterdir()) == []


def test_modes_are_explicit_under_umask_000(tmp_path: Path) -> None:
    out_dir = tmp_path / "robot" / "units"  # the folder above is made too
    code, out = export(tmp_path, out_dir, umask=0)
    assert code == 0, out
    assert stat.S_IMODE(out_dir.parent.stat().st_mode) == 0o755
    assert stat.S_IMODE(out_dir.stat().st_mode) == 0o755
    assert stat.S_IMODE((out_dir / "demo-worker-1.service").stat().st_mode) == 0o644
    assert stat.S_IMODE((out_dir / "demo.target").stat().st_mode) == 0o644
    assert stat.S_IMODE((out_dir / "demo.env").stat().st_mode) == 0o600
