"""``engine.spawning.start`` gives the child ``subprocess.Popen(..., start_new_session=True,
close_fds=True)`` gives, and raises what Popen raises: each check runs both and compares."""

from __future__ import annotations

import ast
import json
import os
import resource
import signal
import subprocess
import sys
import time
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

import pytest

from mlaunch.engine import spawning

pytestmark = pytest.mark.skipif(not spawning.AVAILABLE, reason="no known fork_exec here")

PY = sys.executable


class Child:
    """A started child with its stdin write end and stdout/stderr read ends."""

    def __init__(self, pid: int, stdin: int, stdout: int, stderr: int) -> None:
        self.pid, self.stdin, self.stdout, self.stderr = pid, stdin, stdout, stderr

    def read_line(self, deadline: float = 30.0) -> bytes:
        end = time.monotonic() + deadline
        buf = b""
        while not buf.endswith(b"\n"):
            assert time.monotonic() < end, f"no line from the child: {buf!r}"
            part = os.read(self.stdout, 1)
            if not part:
                break
            buf += part
        return buf

    def finish(self) -> tuple[int, bytes, bytes]:
        """Close stdin, read everything, reap: (exit code, stdout, stderr)."""
        if self.stdin >= 0:
            os.close(self.stdin)
            self.stdin = -1
        out = _read_all(self.stdout)
        err = _read_all(self.stderr)
        _, status = os.waitpid(self.pid, 0)
        return os.waitstatus_to_exitcode(status), out, err


def _read_all(fd: int) -> bytes:
    chunks = []
    while chunk := os.read(fd, 65536):
        chunks.append(chunk)
    os.close(fd)
    return b"".join(chunks)


def launch(
    argv: Sequence[str],
    env: Mapping[str, str] | spawning.Environment,
    **kwargs: object,
) -> Child:
    stdin_r, stdin_w = os.pipe()
    out_r, out_w = os.pipe()
    err_r, err_w = os.pipe()
    try:
        pid = spawning.start(argv, env, stdin=stdin_r, stdout=out_w, stderr=err_w, **kwargs)  # type: ignore[arg-type]
    except BaseException:
        for fd in (stdin_w, out_r, err_r):
            os.close(fd)
        raise
    finally:
        for fd in (stdin_r, out_w, err_w):
            os.close(fd)
    return Child(pid, stdin_w, out_r, err_r)


def run(
    argv: Sequence[str], env: Mapping[str, str] | spawning.Environment, **kwargs: object
) -> tuple[int, bytes]:
    code, out, err = launch(argv, env, **kwargs).finish()
    return code, out + err


def popen_run(argv: Sequence[str], env: Mapping[str, str], **kwargs: object) -> tuple[int, bytes]:
    proc = subprocess.Popen(
        list(argv),
        env=env,
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        start_new_session=True,
        close_fds=True,
        **kwargs,  # type: ignore[call-overload]
    )
    out, _ = proc.communicate()
    return proc.returncode, out


def failure(start: Callable[[], object]) -> tuple[type, int | None, str | None, object]:
    with pytest.raises(OSError) as info:
        start()
    e = info.value
    return type(e), e.errno, e.strerror, e.filename


def script(path: Path, text: str, mode: int = 0o755) -> Path:
    path.write_text(text)
    path.chmod(mode)
    return path


BASE_ENV = {"PATH": os.environ.get("PATH", os.defpath), "LC_ALL": "C"}


def test_argv_and_environment_reach_the_child_as_given() -> None:
    env = {"A": "1", "EMPTY": "", "UNICODE": "héllo ✓", "SPACES": "a b  c", "PATH": "/nowhere"}
    # -S: no site, so the ROS wheels' hook does not re-exec it with a library path added.
    argv = [PY, "-S", "-c", "import json, os, sys; print(json.dumps([sys.argv, dict(os.environ)]))"]
    argv += ["two words", "", "ü"]
    code, out = run(argv, env)
    got_argv, got_env = json.loads(out)
    assert code == 0
    assert got_argv[1:] == ["two words", "", "ü"]
    # The child's environment is exactly env: nothing of ours added or left out (Python may
    # add LC_CTYPE when it coerces the C locale; none of these names is set here).
    assert {k: v for k, v in got_env.items() if k != "LC_CTYPE"} == env


def test_a_prepared_environment_starts_the_same_child_every_time() -> None:
    prepared = spawning.Environment({"X": "1", "PATH": "/nowhere"})
    argv = [PY, "-c", "import os; print(os.environ['X'])"]
    assert run(argv, prepared) == (0, b"1\n")
    assert run(argv, prepared) == (0, b"1\n")


def test_the_program_is_found_on_the_child_environment_s_path(tmp_path: Path) -> None:
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    script(bin_dir / "hello-spawn", '#!/bin/sh\necho found "$@"\n')
    assert str(bin_dir) not in os.environ.get("PATH", "")
    env = {"PATH": f"/nonexistent:{bin_dir}"}
    assert (
        run(["hello-spawn", "x"], env)
        == popen_run(["hello-spawn", "x"], env)
        == (
            0,
            b"found x\n",
        )
    )


def test_a_non_executable_file_earlier_on_path_is_passed_over_as_popen_does(tmp_path: Path) -> None:
    first, second = tmp_path / "first", tmp_path / "second"
    first.mkdir()
    second.mkdir()
    script(first / "prog", "#!/bin/sh\necho first\n", mode=0o644)
    script(second / "prog", "#!/bin/sh\necho second\n")
    env = {"PATH": f"{first}:{second}"}
    assert run(["prog"], env) == popen_run(["prog"], env) == (0, b"second\n")


def test_the_path_lookup_sees_a_program_installed_after_the_first_start(tmp_path: Path) -> None:
    """The cache keeps the candidates of (name, PATH), not which of them existed."""
    env = {"PATH": str(tmp_path)}
    with pytest.raises(FileNotFoundError):
        launch(["late-prog"], env)
    script(tmp_path / "late-prog", "#!/bin/sh\necho late\n")
    assert run(["late-prog"], env) == (0, b"late\n")


def _cases(tmp_path: Path) -> dict[str, tuple[list[str], dict[str, str]]]:
    plain = script(tmp_path / "plain.txt", "not a program\n", mode=0o644)
    garbage = script(tmp_path / "garbage", "\x00\x01\x02 not an executable format\n")
    (tmp_path / "dir-prog").mkdir()
    return {
        "missing on PATH": (["no-such-program-xyz"], {"PATH": str(tmp_path)}),
        "missing, with a tmp_path": ([str(tmp_path / "nope")], BASE_ENV),
        "relative, missing": (["./nope-here"], BASE_ENV),
        "not executable": ([str(plain)], BASE_ENV),
        "not executable, on PATH": (["plain.txt"], {"PATH": str(tmp_path)}),
        "a tmp_path on PATH": (["dir-prog"], {"PATH": str(tmp_path)}),
        "a tmp_path": ([str(tmp_path / "dir-prog")], BASE_ENV),
        "not an executable format": ([str(garbage)], BASE_ENV),
        "no PATH, not in the default one": (["no-such-program-xyz"], {}),
        "empty PATH entry, missing": (["nope-here"], {"PATH": ""}),
        "a file as a tmp_path": ([str(plain / "x")], BASE_ENV),
    }


@pytest.mark.parametrize(
    "case",
    [
        "missing on PATH",
        "missing, with a tmp_path",
        "relative, missing",
        "not executable",
        "not executable, on PATH",
        "a tmp_path on PATH",
        "a tmp_path",
        "not an executable format",
        "no PATH, not in the default one",
        "empty PATH entry, missing",
        "a file as a tmp_path",
    ],
)
def test_a_program_that_cannot_start_raises_what_popen_raises(tmp_path: Path, case: str) -> None:
    argv, env = _cases(tmp_path)[case]
    ours = failure(lambda: launch(argv, env))
    theirs = failure(lambda: popen_run(argv, env))
    assert ours == theirs
    assert issubclass(ours[0], OSError) and ours[1]


def test_the_errors_are_the_engine_s_familiar_ones(tmp_path: Path) -> None:
    plain = script(tmp_path / "plain", "x\n", mode=0o644)
    assert failure(lambda: launch(["no-such-program-xyz"], {"PATH": str(tmp_path)}))[:3] == (
        FileNotFoundError,
        2,
        "No such file or directory",
    )
    assert failure(lambda: launch([str(plain)], BASE_ENV))[:4] == (
        PermissionError,
        13,
        "Permission denied",
        str(plain),
    )


def test_a_working_directory_is_entered_or_its_failure_named_as_popen_does(tmp_path: Path) -> None:
    argv = [PY, "-c", "import os; print(os.getcwd())"]
    assert run(argv, BASE_ENV, cwd=str(tmp_path)) == (0, f"{tmp_path}\n".encode())
    missing = str(tmp_path / "gone")
    ours = failure(lambda: launch(argv, BASE_ENV, cwd=missing))
    assert ours == failure(lambda: popen_run(argv, BASE_ENV, cwd=missing))
    assert ours[0] is FileNotFoundError and ours[3] == missing


def test_no_failed_child_is_left_to_reap(tmp_path: Path) -> None:
    """A child that could not exec is reaped before the error is raised (as Popen does)."""
    for _ in range(3):
        with pytest.raises(FileNotFoundError):
            launch(["no-such-program-xyz"], {"PATH": str(tmp_path)})
    with pytest.raises(ChildProcessError):
        os.waitpid(-1, os.WNOHANG)


def test_the_child_leads_a_session_of_its_own() -> None:
    argv = [PY, "-c", "import os; print(os.getsid(0), os.getpgid(0), os.getpid())"]
    child = launch(argv, BASE_ENV)
    code, out, _ = child.finish()
    assert code == 0
    sid, pgid, pid = map(int, out.split())
    assert sid == pgid == pid == child.pid
    assert sid != os.getsid(0)


def _fds_of(pid: int) -> dict[int, str]:
    folder = f"/proc/{pid}/fd"
    return {int(n): os.readlink(f"{folder}/{n}") for n in os.listdir(folder)}


def test_only_fds_0_to_2_are_inherited_even_an_inheritable_one() -> None:
    """What close_fds=True guarantees: a fd a C library left inheritable (rclpy and Fast DDS
    leave sockets and shared-memory locks so) does not reach the child."""
    leaky_r, leaky_w = os.pipe()
    os.set_inheritable(leaky_r, True)
    os.set_inheritable(leaky_w, True)
    held = open(os.devnull)  # noqa: SIM115  a close-on-exec file, as Python opens every file
    try:
        child = launch(["cat"], BASE_ENV)
        try:
            # start returns once the child has exec'd: its fd table is what the program got.
            fds = _fds_of(child.pid)
            assert sorted(fds) == [0, 1, 2], fds
            assert fds[0].startswith("pipe:") and fds[1].startswith("pipe:")
        finally:
            assert child.finish()[0] == 0
    finally:
        held.close()
        os.close(leaky_r)
        os.close(leaky_w)


def test_stdin_is_the_given_pipe_and_stays_open_until_the_writer_closes_it() -> None:
    """A child reading stdin waits for what is written, and reads EOF only at the close."""
    code = (
        "import sys\n"
        "for line in sys.stdin:\n"
        "    print('got', line.strip(), flush=True)\n"
        "print('eof', flush=True)\n"
    )
    child = launch([PY, "-c", code], BASE_ENV)
    os.write(child.stdin, b"one\n")
    assert child.read_line() == b"got one\n"
    os.write(child.stdin, b"two\n")
    assert child.read_line() == b"got two\n"
    code_, out, err = child.finish()
    assert (code_, out, err) == (0, b"eof\n", b"")


def _signal_masks(status: str) -> dict[str, int]:
    return {
        line.split(":")[0]: int(line.split()[1], 16)
        for line in status.splitlines()
        if line.startswith(("SigIgn", "SigBlk"))
    }


def test_sigpipe_and_sigxfsz_are_back_to_their_defaults_as_with_popen() -> None:
    ours = _signal_masks(run(["cat", "/proc/self/status"], BASE_ENV)[1].decode())
    theirs = _signal_masks(popen_run(["cat", "/proc/self/status"], BASE_ENV)[1].decode())
    assert ours == theirs
    for sig in (signal.SIGPIPE, signal.SIGXFSZ):
        assert not ours["SigIgn"] & (1 << (sig - 1))
    assert signal.getsignal(signal.SIGPIPE) == signal.SIG_IGN  # Python's own, unchanged


def test_child_setup_runs_in_the_child_before_exec() -> None:
    soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    lower = min(soft, 200)

    def restore() -> None:
        resource.setrlimit(resource.RLIMIT_NOFILE, (lower, hard))

    argv = [PY, "-c", "import resource; print(resource.getrlimit(resource.RLIMIT_NOFILE)[0])"]
    assert run(argv, BASE_ENV, child_setup=restore) == (0, f"{lower}\n".encode())
    assert resource.getrlimit(resource.RLIMIT_NOFILE) == (soft, hard)


def test_a_child_setup_that_raises_is_an_os_error_not_a_crash() -> None:
    def broken() -> None:
        raise RuntimeError("no")

    with pytest.raises(spawning.ChildSetupFailed) as info:
        launch(["true"], BASE_ENV, child_setup=broken)
    assert "preexec_fn" in str(info.value)


def test_a_bad_environment_name_is_refused_as_popen_refuses_it() -> None:
    with pytest.raises(ValueError, match="illegal environment variable name"):
        launch(["true"], {"A=B": "1"})
    with pytest.raises(ValueError, match="illegal environment variable name"):
        popen_run(["true"], {"A=B": "1"})


def test_a_fd_below_3_for_the_error_pipe_is_moved_out_of_the_way() -> None:
    """Started with fd 0 closed, the error pipe's first end would be 0: the child must still
    get its stdin (and the error report must still work)."""
    code = (
        "import os, sys\n"
        f"sys.path.insert(0, {str(Path(spawning.__file__).parents[2])!r})\n"
        "from mlaunch.engine import spawning\n"
        "os.close(0)\n"
        "r, w = os.pipe(); o_r, o_w = os.pipe()\n"
        "os.write(w, b'hi'); os.close(w)\n"
        "pid = spawning.start(['cat'], {'PATH': os.environ['PATH']}, stdin=r, stdout=o_w,"
        " stderr=2)\n"
        "os.close(o_w); os.close(r); os.waitpid(pid, 0)\n"
        "print(os.read(o_r, 100).decode())\n"
        "try:\n"
        "    spawning.start(['no-such-xyz'], {'PATH': '/'}, stdin=2, stdout=2, stderr=2)\n"
        "except FileNotFoundError as e:\n"
        "    print('raised', e.errno)\n"
    )
    out = subprocess.run(
        [PY, "-c", code], capture_output=True, check=True, timeout=60, stdin=subprocess.DEVNULL
    )
    assert out.stdout.split() == [b"hi", b"raised", b"2"]


def test_the_module_imports_only_os_sys_errno_and_the_c_spawner() -> None:
    """A start path that spawns before the engine loads pays for nothing else."""
    tree = ast.parse(Path(spawning.__file__).read_text())
    imported: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            imported.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            imported.add(node.module or "")
    assert imported <= {"__future__", "os", "sys", "errno", "_posixsubprocess",
                        "collections.abc"}, imported  # fmt: skip
    probe = (
        "import sys; before = set(sys.modules)\n"
        "import mlaunch.engine.spawning\n"
        "print(' '.join(sorted(set(sys.modules) - before)))\n"
    )
    out = subprocess.run([PY, "-c", probe], capture_output=True, text=True, check=True)
    new = set(out.stdout.split())
    assert "subprocess" not in new and "typing" not in new and "collections.abc" not in new
    assert {m for m in new if m.startswith("mlaunch")} == {
        "mlaunch",
        "mlaunch.engine",
        "mlaunch.engine.spawning",
    }


def test_an_unknown_fork_exec_is_not_used(monkeypatch: pytest.MonkeyPatch) -> None:
    """The private function's parameters are checked before use: one more, one fewer or
    reordered (a future Python) turns the module off instead of mis-binding them."""
    import _posixsubprocess

    class Fake:
        def __init__(self, signature: str | None) -> None:
            self.__text_signature__ = signature

        def __call__(self, *args: object) -> int:
            raise AssertionError("must not be called")

    right = "($module, " + spawning._PARAMETERS + ", /)"
    monkeypatch.setattr(sys, "version_info", (3, 12, 0))
    monkeypatch.setattr(_posixsubprocess, "fork_exec", Fake(right))
    assert spawning._fork_exec() is not None
    for wrong in (
        right.replace(", allow_vfork", ""),
        right.replace("cwd, env", "env, cwd"),
        right.replace("preexec_fn", "preexec_fn, pidfd"),
        None,
    ):
        monkeypatch.setattr(_posixsubprocess, "fork_exec", Fake(wrong))
        assert spawning._fork_exec() is None, wrong


def test_equal_environments_are_encoded_once_and_a_change_is_seen() -> None:
    base = {"PATH": "/nowhere", "A": "1"}
    first = spawning.environment(dict(base))
    assert spawning.environment(dict(base)) is first  # equal content, another dict
    changed = spawning.environment({**base, "A": "2"})
    assert changed is not first
    argv = [PY, "-S", "-c", "import os; print(os.environ['A'])"]
    assert run(argv, first) == (0, b"1\n")
    assert run(argv, changed) == (0, b"2\n")


def test_bytes_and_paths_in_the_environment_are_taken_as_popen_takes_them() -> None:
    env = {b"RAW": b"\xff", "P": Path("/x/y")}
    argv = [PY, "-S", "-c", "import os; print(os.environb[b'RAW'], os.environ['P'])"]
    assert run(argv, env) == popen_run(argv, env) == (0, b"b'\\xff' /x/y\n")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="illegal environment variable name"):
        launch(["true"], {b"A=B": b"1"})  # type: ignore[dict-item]


def test_the_audit_event_is_popen_s() -> None:
    """Audit hooks see a start as they see Popen's: ``subprocess.Popen`` with the program,
    the arguments, the working directory and the environment mapping."""
    code = (
        "import sys\n"
        f"sys.path.insert(0, {str(Path(spawning.__file__).parents[2])!r})\n"
        "from mlaunch.engine import spawning\n"
        "seen = []\n"
        "sys.addaudithook(lambda e, a: seen.append(a) if e == 'subprocess.Popen' else None)\n"
        "env = {'PATH': '/bin:/usr/bin', 'A': '1'}\n"
        "import os\n"
        "pid = spawning.start(['true', 'x'], spawning.environment(env), stdin=0, stdout=1,"
        " stderr=2, cwd='/')\n"
        "os.waitpid(pid, 0)\n"
        "print(seen)\n"
    )
    out = subprocess.run(
        [PY, "-S", "-c", code], capture_output=True, text=True, check=True, timeout=60
    )
    assert (
        out.stdout.strip() == "[('true', ['true', 'x'], '/', {'PATH': '/bin:/usr/bin', 'A': '1'})]"
    )


def test_bytes_and_path_arguments_are_taken_as_popen_takes_them(tmp_path: Path) -> None:
    prog = script(tmp_path / "prog", '#!/bin/sh\necho "$@"\n')
    env = {"PATH": str(tmp_path)}
    for argv in ([b"prog", b"a"], [prog, "b"], [os.fsencode(prog), "c"]):
        assert run(argv, env) == popen_run(argv, env)  # type: ignore[arg-type]
    for missing in ([b"no-such-xyz"], [tmp_path / "nope"]):
        ours = failure(lambda m=missing: launch(m, env))  # type: ignore[misc]
        assert ours == failure(lambda m=missing: popen_run(m, env))  # type: ignore[misc]
