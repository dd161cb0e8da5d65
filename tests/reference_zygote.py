"""``ros2 launch`` runs forked from one reference interpreter that imported ros2cli, launch and
launch_ros once (tests/reference.py starts it with the reference's python and talks to it).

Each ``ros2`` command line is still a process of its own: a child forked before anything ran,
in a session of its own, with the run's environment, folder, stdin from /dev/null and stdout
and stderr to the files the caller named; it calls ros2cli's ``main`` as the ``ros2`` script
does and exits the way ``sys.exit`` makes the script exit. What the fork saves is the imports
(about 0.3 s of CPU of the 0.36 s an empty launch costs). Only variables that launch reads when
it runs may differ from the server's own: those the server was started with are what the
interpreter, its locale and its imports saw.

Protocol: one JSON request a line on stdin ({"argv", "env", "cwd", "stdout", "stderr"}); the
answer is two lines on stdout, {"pid": PID} as the child starts and {"status": N} as it ends
(N: its exit status, or minus the signal that ended it). End of stdin ends the server.
"""

from __future__ import annotations

import atexit
import json
import os
import signal
import sys

# What `ros2 launch` imports before it reads a launch file (the fork keeps them loaded).
import launch  # noqa: F401
import launch_ros
import launch_ros.actions  # noqa: F401
import ros2launch.api
import ros2launch.command.launch  # noqa: F401
from ros2cli.cli import main


def _child(request: dict[str, object]) -> None:
    """The forked child: become the ``ros2`` process of the request, run it and exit."""
    os.setsid()
    devnull = os.open(os.devnull, os.O_RDONLY)
    os.dup2(devnull, 0)
    for fd, path in ((1, request["stdout"]), (2, request["stderr"])):
        target = os.open(str(path), os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
        os.dup2(target, fd)
        os.close(target)
    os.close(devnull)
    os.chdir(str(request["cwd"]))
    env = request["env"]
    assert isinstance(env, dict)
    os.environ.clear()
    os.environ.update(env)
    argv = request["argv"]
    assert isinstance(argv, list)
    sys.argv = [str(a) for a in argv]
    # What the ros2 script does: sys.exit(main()), its status as SystemExit makes it.
    try:
        sys.exit(main())
    except SystemExit as exit_:
        code = exit_.code
        status = code if isinstance(code, int) else 0 if code is None else 1
        if not isinstance(code, int | None):
            print(code, file=sys.stderr)
    except KeyboardInterrupt:  # the interpreter ends by its SIGINT then: status -2
        sys.excepthook(*sys.exc_info())
        status = -signal.SIGINT
    except BaseException:
        sys.excepthook(*sys.exc_info())
        status = 1
    # The interpreter's exit handlers (logging's flush, launch's), then no C-level teardown: the
    # libraries the fork inherited loaded (rclpy's) crashed in their destructors (status -11).
    atexit._run_exitfuncs()
    for stream in (sys.stdout, sys.stderr):
        stream.flush()
    if status == -signal.SIGINT:
        signal.signal(signal.SIGINT, signal.SIG_DFL)
        os.kill(os.getpid(), signal.SIGINT)
    os._exit(status & 0xFF)


def serve() -> None:
    for line in sys.stdin:
        if not line.strip():
            continue
        request = json.loads(line)
        sys.stdout.flush()
        pid = os.fork()
        if pid == 0:
            _child(request)
        print(json.dumps({"pid": pid}), flush=True)
        _, status = os.waitpid(pid, 0)
        print(json.dumps({"status": os.waitstatus_to_exitcode(status)}), flush=True)


if __name__ == "__main__":
    serve()
