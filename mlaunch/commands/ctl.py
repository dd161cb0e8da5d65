"""``mlaunch ctl [RUN] list|stop|start|restart|mute|unmute|logs [LABEL]``: control a running launch;
``mlaunch ctl wait-ready [RUN] [--timeout S]``: wait until it is ready (mlaunch.commands.readiness).

Another shell talks to a running mlaunch through its control socket (mlaunch.parts.control_socket,
in the run's log folder, private to the user). RUN picks the run: by default the newest one that
is still running; else a log folder (a path, or a folder name or part of one under the log
base), mlaunch's pid, or the run id (``MLAUNCH_RUN_ID`` of its processes). What each operation
does is mlaunch.parts.control's; this module finds the run, sends the request and says the answer.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import socket
import sys

from mlaunch.commands.ctl_error import CtlError
from mlaunch.engine.logfiles import log_base_dir
from mlaunch.parts.control import DEFAULT_LINES, OPERATIONS
from mlaunch.parts.control_socket import FOLDER, NAME, PROTOCOL, READY, Address
from mlaunch.plan.argparser import ArgumentParser
from mlaunch.plan.errors import EXIT_FAILURE, EXIT_OK, EXIT_USAGE, did_you_mean

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING
if TYPE_CHECKING:
    from collections.abc import Mapping, Sequence

# How long the run may take to take a request (its loop answers between two turns).
ANSWER_TIMEOUT = 5.0
# The longest answer line read (a logs answer is at most a few MiB of JSON).
MAX_ANSWER = 64 * 1024 * 1024
RUN_ID = re.compile(r"(\d+)-[0-9a-f]{8}")
WAIT_READY = "wait-ready"
DEFAULT_READY_TIMEOUT = 60.0
# How often wait-ready asks the run (or looks for it, before it is there).
READY_POLL = 0.2

DESCRIPTION = """\
Control a running launch from another shell: list its processes, stop, start or restart one,
keep one's output off mlaunch's screen (mute) or show it again (unmute), or print its last lines.
"""

EPILOG = """\
operations:
  list            every process: state, pid, restarts, uptime, muted, how it last ended
  stop LABEL      stop it with its stop ladder (SIGINT, SIGTERM, SIGKILL); it stays down,
                  respawn included, and is reported as stopped by the user
  start LABEL     start a process that is not running again (same label, argv, parameters)
  restart LABEL   stop it, then start it at once (no respawn delay); restarts + 1
  mute LABEL      keep its output off mlaunch's screen; its log file still gets every line
  unmute LABEL    show its output again
  logs LABEL      its last lines (-n)
  unload NODE     ask its container to unload the composable node NODE (its full name, or
                  its name when only one has it)
  load NODE       load it into its container again (after an unload, or a failed load)
  configure|activate|deactivate|cleanup NODE
                  ask the lifecycle node NODE for that transition
  wait-ready      wait until the launch is ready by mlaunch test's checks (processes up, nodes
                  in the graph, lifecycle nodes active, /clock under sim time, the file's own
                  expectations); a run that is not there yet is waited for (--timeout)

LABEL: a process's label (talker-1, as mlaunch prints it), or its name without the counter
(talker) or its node's name, when only one process has it.

RUN (default: the newest run still running, under the ROS log folder):
  a run's log folder, or its name (latest too) or part of it; mlaunch's pid; or the run id
  (MLAUNCH_RUN_ID in its processes' environment)

exit status:
  0  done
  1  the run or the process cannot do it now: no running launch, the launch ended (a stale
     control socket), the process is not running or already running, the launch is
     shutting down
  2  bad input: an unknown operation or label, a RUN that names nothing or several runs

wait-ready: 0 ready; 1 not ready when --timeout passed (what is missing is said), a check
failed (a process it watches died) or the run ended; 2 no such run within --timeout

A launch whose processes were all stopped this way keeps running (they can be started again);
Ctrl-C ends it. The launch file's exit handlers see each stop as they would see ros2 launch's
ShutdownProcess: a process with on_exit=Shutdown() (XML on_exit="shutdown") ends the launch
when it is stopped or restarted, with exit status 0.
"""


def parser() -> argparse.ArgumentParser:
    p = ArgumentParser(
        prog="mlaunch ctl",
        usage="mlaunch ctl [-h] [-n LINES] [--json] [--timeout S] [RUN] OPERATION [LABEL]",
        description=DESCRIPTION,
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("words", nargs="+", metavar="[RUN] OPERATION [LABEL]", help="see below")
    p.add_argument(
        "-n",
        "--lines",
        type=int,
        default=DEFAULT_LINES,
        help=f"logs: how many of the last lines (default: {DEFAULT_LINES})",
    )
    p.add_argument("--json", action="store_true", help="print the answer as JSON (one object)")
    p.add_argument(
        "--timeout",
        type=float,
        default=DEFAULT_READY_TIMEOUT,
        metavar="S",
        help=f"wait-ready: how long to wait (default: {DEFAULT_READY_TIMEOUT:g} s)",
    )
    p.add_argument("-d", "--debug", action="store_true", help="show tracebacks of errors")
    return p


def split_words(words: Sequence[str]) -> tuple[str | None, str, str | None]:
    """(RUN, operation, LABEL) from ``[RUN] OPERATION [LABEL]``."""
    if words[0] in OPERATIONS:
        run, rest = None, list(words)
    elif len(words) > 1 and words[1] in OPERATIONS:
        run, rest = words[0], list(words[1:])
    else:
        # The operation is the middle word of three, else the first (or the second: RUN list).
        hint = next(
            filter(None, (did_you_mean(w, OPERATIONS) for w in words[len(words) > 2 :])), ""
        )
        raise CtlError(
            f"no operation in {' '.join(words)!r}{hint}; valid: {', '.join(OPERATIONS)}",
            EXIT_USAGE,
        )
    op, args = rest[0], rest[1:]
    if op == "list":
        if args:
            raise CtlError(f"list takes no label (got {args[0]!r})", EXIT_USAGE)
        return run, op, None
    if len(args) != 1:
        what = "one process label" if not args else f"one label, not {len(args)}"
        raise CtlError(f"{op} needs {what}: mlaunch ctl [RUN] {op} LABEL", EXIT_USAGE)
    return run, op, args[0]


def command(args: Sequence[str]) -> int:
    """``mlaunch ctl ...``: find the run, send the request, say the answer; raises on failure."""
    # Intermixed: options go anywhere, as the README writes them (ctl logs -n 3 talker).
    ns = parser().parse_intermixed_args(list(args))
    if WAIT_READY in ns.words[:2]:
        return wait_ready(ns.words, ns.timeout, as_json=ns.json)
    run, op, label = split_words(ns.words)
    request: dict[str, object] = {"version": PROTOCOL, "op": op}
    if label is not None:
        request["label"] = label
    if op == "logs":
        request["lines"] = ns.lines
    try:
        target = find_run(run, os.environ)
        answer = ask(target, request)
        expected_id = _run_id(run)
        about = answer.get("run")
        if expected_id and (not isinstance(about, dict) or about.get("run_id") != expected_id):
            raise CtlError(f"the run in {target.folder} is not run {expected_id}", EXIT_USAGE)
    except CtlError as e:
        if ns.json:  # machine output for every failure, not only the run's answers
            failed = {"ok": False, "error": str(e), "status": e.exit_code}
            sys.stdout.write(json.dumps(failed, indent=2) + "\n")
        raise
    if ns.json:
        sys.stdout.write(json.dumps(answer, indent=2) + "\n")
    if not answer.get("ok"):
        status = answer.get("status")
        raise CtlError(str(answer.get("error")), status if isinstance(status, int) else 1)
    if not ns.json:
        sys.stdout.write(say(op, answer))
    if "limit" in answer:
        sys.stderr.write(
            f"mlaunch ctl: only the last {answer['limit']} lines (a request gets at most that"
            f" many, and 4 MiB); every line is in {label}'s log file in {target.folder}\n"
        )
    return EXIT_OK


# --- wait-ready -----------------------------------------------------------------------------------


def wait_ready(words: Sequence[str], timeout: float, *, as_json: bool) -> int:
    """``wait-ready [RUN]`` (or ``RUN wait-ready``): 0 ready, 1 not ready, 2 no such run."""
    import time

    rest = [w for w in words if w != WAIT_READY]
    if len(rest) > 1 or len(words) - len(rest) != 1:
        raise CtlError(f"wait-ready takes at most one RUN (got {' '.join(words)!r})", EXIT_USAGE)
    if not timeout >= 0 or timeout == float("inf"):
        raise CtlError(f"--timeout {timeout!r}: expected a number of seconds >= 0", EXIT_USAGE)
    run = rest[0] if rest else None
    deadline = time.monotonic() + timeout
    found, answer, error = False, None, None
    while True:
        try:
            target = find_run(run, os.environ)
            found = True
            answer = ask(target, {"version": PROTOCOL, "op": READY})
            if not answer.get("ok"):  # the run cannot tell (a mlaunch test run): no waiting
                error, answer = CtlError(f"{target.folder}: {answer.get('error')}"), None
                break
            error = None
            if answer.get("ready") or answer.get("failed"):
                break
        except CtlError as e:
            error = e
            if e.exit_code == EXIT_FAILURE and run is not None:
                found = True  # its folder is there: not running (yet, or any more)
            if run is not None and run.isdigit() and found and not _alive(int(run)):
                error = CtlError(f"run {run} ended before it was ready ({e})")
                break
        left = deadline - time.monotonic()
        if left <= 0:
            break
        time.sleep(min(READY_POLL, left))
    return _say_ready(answer, error, found, timeout, as_json)


def _alive(pid: int) -> bool:
    """Whether ``pid`` runs (a zombie, ended but not yet reaped by its parent, does not)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    try:
        with open(f"/proc/{pid}/stat", encoding="utf-8", errors="replace") as f:
            return f.read().rsplit(") ", 1)[1][:1] != "Z"
    except (OSError, IndexError):
        return True


def _say_ready(
    answer: dict[str, object] | None,
    error: CtlError | None,
    found: bool,
    timeout: float,
    as_json: bool,
) -> int:
    ready = bool(answer and answer.get("ready"))
    if ready:
        status = EXIT_OK
    elif answer is None and not found:
        status = EXIT_USAGE
    else:
        status = EXIT_FAILURE
    out: dict[str, object] = dict(answer or {})
    out.update(ok=ready, status=status, ready=ready)
    if not ready and error is not None:
        out["error"] = str(error)  # the last word: the run ended, or cannot tell
    elif not ready and not out.get("failed"):
        out["error"] = f"not ready after {timeout:g} s"
    if as_json:
        sys.stdout.write(json.dumps(out, indent=2) + "\n")
        return status
    if ready:
        sys.stdout.write(f"{answer.get('summary') if answer else 'ready'}\n")
        return status
    lines = [f"mlaunch ctl: wait-ready: {out.get('error') or out.get('failed')}"]
    for check in answer.get("checks", []) if answer else []:  # type: ignore[attr-defined]
        if check.get("state") != "met":
            lines.append(f"  {check['state']}: {check['description']} (seen: {check['seen']})")
    sys.stderr.write("\n".join(lines) + "\n")
    return status


# --- finding the run ------------------------------------------------------------------------------


class Target:
    """A run's control socket: ``folder`` is the run's log folder."""

    __slots__ = ("folder", "folder_known", "path")

    def __init__(self, folder: str, path: str, *, folder_known: bool = True) -> None:
        self.folder = folder
        self.path = path
        # False when the user named the socket itself: its run's folder is a guess.
        self.folder_known = folder_known


def find_run(run: str | None, environ: Mapping[str, str]) -> Target:
    """The run RUN names (None: the newest still running) under the ROS log folder; only
    through folders, files and links of the caller's own (mlaunch.commands.ctl_trust)."""
    from mlaunch.commands.ctl_trust import own_entry

    base = log_base_dir(environ)
    if run is None:
        return _newest_live(base)
    under_base = os.path.join(base, run)  # a folder's name, or "latest"
    if os.path.exists(run) or (os.sep not in run and os.path.isdir(under_base)):
        given = run if os.path.exists(run) else under_base
        path = os.path.realpath(given)
        if os.path.isdir(path):
            why = own_entry(given.rstrip(os.sep) or given)
            if why:
                raise CtlError(f"{why}; not a run of yours: nothing was sent to it")
            return _with_socket(path)
        return Target(os.path.dirname(os.path.dirname(path)), path, folder_known=False)
    pid = run if run.isdigit() else None
    match = RUN_ID.fullmatch(run)
    if match:
        pid = match.group(1)
    folders = _run_folders(base)
    if pid is not None:
        named = [f for f in folders if f.endswith(f"-{pid}")]
        what = f"pid {pid}"
    else:
        named = [f for f in folders if f == run] or [f for f in folders if run in f]
        what = repr(run)
    if not named:
        recent = ", ".join(folders[:5]) or "none"
        raise CtlError(f"no run {what} under {base} (newest runs: {recent})", EXIT_USAGE)
    live = [f for f in named if _socket_of(os.path.join(base, f))[0]]
    if len(named) > 1 and len(live) != 1:
        shown = ", ".join(named[:10]) + (f" and {len(named) - 10} more" if len(named) > 10 else "")
        raise CtlError(f"{what} names {len(named)} runs: {shown}; give one folder", EXIT_USAGE)
    return _with_socket(os.path.join(base, (live or named)[0]))


def _socket_of(folder: str) -> tuple[str | None, str]:
    from mlaunch.commands.ctl_trust import locate

    return locate(folder)


def _with_socket(folder: str) -> Target:
    path, why = _socket_of(folder)
    if why:
        raise CtlError(f"{why}; not a run of yours: nothing was sent to it")
    if path is None:
        raise CtlError(
            f"the run in {folder} is not running (its control socket {FOLDER}/{NAME} is gone)"
        )
    return Target(folder, path)


def _run_folders(base: str) -> list[str]:
    """Run log folders under ``base``, newest first (their names start with the time)."""
    try:
        names = [e.name for e in os.scandir(base) if e.is_dir(follow_symlinks=False)]
    except OSError:
        return []
    return sorted(names, reverse=True)


def _newest_live(base: str) -> Target:
    """The newest run of the caller's that answers; stale sockets are skipped, and named if
    nothing answers; other users' sockets are skipped (never connected to), and named too."""
    from mlaunch.commands.ctl_trust import own_entry, untrusted

    candidates = []
    latest = os.path.join(base, "latest")
    if os.path.lexists(latest) and not own_entry(latest):  # only a link of the caller's own
        candidates.append(os.path.realpath(latest))
    candidates += [os.path.join(base, name) for name in _run_folders(base)]
    stale: list[str] = []
    foreign: list[str] = []
    seen = set()
    for folder in candidates:
        path, why = _socket_of(folder) if folder not in seen else (None, "")
        seen.add(folder)
        if path is None:
            if why and os.path.lexists(os.path.join(folder, FOLDER)):
                foreign.append(why)
            continue
        why = untrusted(path)
        if why:
            foreign.append(why)
        elif _answers(path):
            return Target(folder, path)
        else:
            stale.append(folder)
    skipped = f"; {len(foreign)} not yours skipped ({foreign[0]})" if foreign else ""
    if stale:
        raise CtlError(
            f"no running launch under {base}: the newest with a control socket, {stale[0]},"
            f" has ended (its socket is stale: nothing accepts on it){skipped}"
        )
    raise CtlError(
        f"no running launch under {base} (no run's log folder has a control socket{skipped})"
    )


def _answers(path: str) -> bool:
    """Whether something accepts on the socket (a dead run's socket refuses at once)."""
    try:
        with _connect(path, ANSWER_TIMEOUT):
            return True
    except OSError:
        return False


def _run_id(run: str | None) -> str | None:
    return run if run is not None and RUN_ID.fullmatch(run) else None


# --- talking to it ----------------------------------------------------------------------------


def _connect(path: str, timeout: float) -> socket.socket:
    """Connected to ``path`` within ``timeout``; a full listen queue (EAGAIN: many clients at
    once) is tried again until then."""
    import time

    deadline = time.monotonic() + timeout
    pause = 0.005
    while True:
        sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        sock.settimeout(max(0.01, deadline - time.monotonic()))
        try:
            with Address(path) as address:
                sock.connect(address)
            return sock
        except BlockingIOError:
            sock.close()
            if time.monotonic() + pause > deadline:
                raise TimeoutError(f"{path}: its queue stayed full for {timeout:g} s") from None
            time.sleep(pause)  # the run's loop accepts between two turns
            pause = min(pause * 2, 0.1)
        except BaseException:
            sock.close()
            raise


def ask(target: Target, request: dict[str, object]) -> dict[str, object]:
    """Send ``request``, return the final answer (after ``accepted``, if the run sends one).

    Only a socket of the caller's own, in a folder only they can write, served by a process of
    theirs (SO_PEERCRED) is asked (mlaunch.commands.ctl_trust); an answer that is not what a run
    sends is an error that says what came.
    """
    from mlaunch.commands.ctl_trust import check_peer, check_place

    check_place(target.path)
    try:
        sock = _connect(target.path, ANSWER_TIMEOUT)
    except (ConnectionRefusedError, FileNotFoundError):
        raise CtlError(
            f"the run in {target.folder} has ended (its control socket is stale)"
        ) from None
    except TimeoutError:
        raise CtlError(f"the run in {target.folder} does not answer (stopped?)") from None
    except OSError as e:
        raise CtlError(f"cannot reach the run in {target.folder}: {e.strerror or e}") from None
    with sock:
        peer = check_peer(sock, target.path)
        try:
            sock.sendall(json.dumps(request).encode() + b"\n")
        except OSError as e:
            raise CtlError(f"the run in {target.folder} took no request: {e.strerror or e}")
        answer = _final_answer(sock, target)
    about = answer.get("run")
    if isinstance(about, dict) and about.get("pid") not in (None, peer):
        raise CtlError(
            f"the control socket {target.path} is served by pid {peer}, but its answer names"
            f" pid {about.get('pid')!r}: not an answer to trust"
        )
    log_dir = about.get("log_dir") if isinstance(about, dict) else None
    if target.folder_known and not _same_folder(log_dir, target.folder):
        raise CtlError(
            f"the control socket {target.path} answered for the run in {log_dir!r}, not for"
            f" {target.folder}: not an answer to trust"
        )
    return answer


def _same_folder(log_dir: object, folder: str) -> bool:
    return isinstance(log_dir, str) and os.path.realpath(log_dir) == os.path.realpath(folder)


def _final_answer(sock: socket.socket, target: Target) -> dict[str, object]:
    reader = sock.makefile("rb")
    while True:
        try:
            line = reader.readline(MAX_ANSWER)
        except TimeoutError:
            raise CtlError(f"the run in {target.folder} did not answer in time") from None
        except OSError as e:
            raise CtlError(f"the run in {target.folder} broke off: {e.strerror or e}") from None
        if not line:
            raise CtlError(f"the run in {target.folder} ended before it answered")
        message = _message(line, target)
        if message.get("accepted") is True:
            wait = message.get("wait", 60.0)
            if not isinstance(wait, (int, float)) or not 0 < wait <= 24 * 3600:
                raise _unexpected(target, line, "its wait is not a number of seconds")
            sock.settimeout(float(wait))
            continue
        if not isinstance(message.get("ok"), bool):
            raise _unexpected(target, line, "it has no 'ok'")
        return message


def _message(line: bytes, target: Target) -> dict[str, object]:
    if not line.endswith(b"\n"):
        raise _unexpected(target, line, f"no end of line within {MAX_ANSWER} bytes")
    try:
        message = json.loads(line)
    except (ValueError, RecursionError) as e:
        raise _unexpected(target, line, f"not JSON ({e})") from None
    if not isinstance(message, dict):
        raise _unexpected(target, line, "not a JSON object")
    return message


def _unexpected(target: Target, line: bytes, why: str) -> CtlError:
    shown = line[:80].decode("utf-8", "replace") + ("..." if len(line) > 80 else "")
    return CtlError(
        f"the control socket {target.path} answered something no mlaunch run sends ({why}):"
        f" {shown.strip()!r}"
    )


# --- saying the answer --------------------------------------------------------------------------


def say(op: str, answer: dict[str, object]) -> str:
    """The answer in words (without --json)."""
    if op == "list":
        return _table(answer.get("processes") or [])  # type: ignore[arg-type]
    if op == "logs":
        lines = answer.get("lines") or []
        return "".join(f"{line}\n" for line in lines)  # type: ignore[attr-defined]
    if op in ("unload", "load"):
        node: dict[str, object] = answer.get("component") or {}  # type: ignore[assignment]
        return f"{node.get('name')}: {node.get('state')} (container {node.get('container')})\n"
    if "lifecycle" in answer:
        managed: dict[str, object] = answer["lifecycle"]  # type: ignore[assignment]
        return f"{managed.get('name')}: {op} done, now {managed.get('state')}\n"
    info: dict[str, object] = answer.get("process") or {}  # type: ignore[assignment]
    label, state = info.get("label"), info.get("state")
    if op in ("mute", "unmute"):
        return f"{label}: {'muted' if info.get('muted') else 'unmuted'}\n"
    if state in ("running", "stopping"):
        return f"{label}: running [pid {info.get('pid')}], restarts: {info.get('restarts')}\n"
    return f"{label}: {info.get('outcome') or state}\n"


def _table(rows: list[dict[str, object]]) -> str:
    head = ("process", "state", "pid", "restarts", "uptime", "muted", "last ended")
    cells = [
        (
            str(r["label"]),
            str(r["state"]),
            str(r["pid"] or "-"),
            str(r["restarts"]),
            _uptime(r["uptime"], r.get("restart_in")),
            "yes" if r["muted"] else "",
            str(r["outcome"] or ""),
        )
        for r in rows
    ]
    widths = [max(len(row[i]) for row in [head, *cells]) for i in range(len(head))]
    return "".join(
        "  ".join(c.ljust(w) for c, w in zip(row, widths, strict=True)).rstrip() + "\n"
        for row in [head, *cells]
    )


def _uptime(value: object, restart_in: object = None) -> str:
    if isinstance(restart_in, (int, float)):
        return f"restart in {restart_in:.1f} s"
    if not isinstance(value, (int, float)):
        return "-"
    from mlaunch.parts.summary import format_duration

    return format_duration(float(value))
