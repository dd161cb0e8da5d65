"""The conformance recorder: a program both launchers start, which writes down how it was started.

Installed as ``lib/conf_pkg/recorder`` in a throw-away ament prefix, so ``Node(package='conf_pkg',
executable='recorder')`` and ``ExecuteProcess(cmd=[...])`` both reach it. It appends one JSON line
to ``$CONF_RECORD_DIR/records.jsonl`` (argv, cwd, the whole environment, the text of every
``--params-file``, whether stdin/stdout are terminals), then behaves as its own options say:

  --say TEXT     print TEXT on stdout (repeatable)
  --err TEXT     print TEXT on stderr (repeatable)
  --wait-for W   first wait (up to 20 s) until another recorded process has the word W in its argv:
                 ordering that does not race the other process's start-up
  --linger S     stay alive S seconds (ended early by SIGINT/SIGTERM, exit 0)
  --exit N       exit with status N (default 0)

SIGINT and SIGTERM are handled before the record is written, so a process that others saw
recorded ends cleanly when the launcher stops it.

Only the standard library: it must start the same under either launcher's interpreter.
"""

import json
import os
import signal
import sys
import time


def _own_options(argv):
    """The recorder's options: everything before --ros-args, leaving the ROS part alone."""
    opts: dict = {"say": [], "err": [], "linger": 0.0, "exit": 0, "wait_for": None}
    args = argv[1:]
    if "--ros-args" in args:
        args = args[: args.index("--ros-args")]
    i = 0
    while i < len(args):
        key = args[i]
        value = args[i + 1] if i + 1 < len(args) else ""
        if key == "--say":
            opts["say"].append(value)
        elif key == "--err":
            opts["err"].append(value)
        elif key == "--linger":
            opts["linger"] = float(value)
        elif key == "--exit":
            opts["exit"] = int(value)
        elif key == "--wait-for":
            opts["wait_for"] = value
        else:
            i += 1
            continue
        i += 2
    return opts


def _params_files(argv):
    texts = []
    for i, arg in enumerate(argv[:-1]):
        if arg == "--params-file":
            try:
                with open(argv[i + 1], encoding="utf-8") as f:
                    texts.append(f.read())
            except OSError as e:
                texts.append(f"<unreadable: {e.strerror}>")
    return texts


def _wait_for(records, word):
    deadline = time.monotonic() + 20
    while time.monotonic() < deadline:
        with open(records, encoding="utf-8") as f:
            others = [json.loads(line) for line in f]
            if any(word in r["argv"] and r["pid"] != os.getpid() for r in others):
                return
        time.sleep(0.01)  # the recorder is the child under test, not a test: polling is fine


def main():
    stop = []
    signal.signal(signal.SIGINT, lambda *_: stop.append(1))
    signal.signal(signal.SIGTERM, lambda *_: stop.append(1))
    if "CONF_RECORD_DIR" not in os.environ:
        sys.exit("recorder: no CONF_RECORD_DIR in the environment, nothing recorded")
    records = os.path.join(os.environ["CONF_RECORD_DIR"], "records.jsonl")
    record = {
        "pid": os.getpid(),
        "argv0": os.path.basename(sys.argv[0]),
        "argv": sys.argv[1:],
        "cwd": os.getcwd(),
        "env": dict(os.environ),
        "params_files": _params_files(sys.argv),
        "stdin_tty": os.isatty(0),
        "stdout_tty": os.isatty(1),
        "stderr_tty": os.isatty(2),
    }
    line = (json.dumps(record, sort_keys=True) + "\n").encode()
    fd = os.open(records, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o644)
    os.write(fd, line)
    os.close(fd)
    opts = _own_options(sys.argv)
    if opts["wait_for"]:
        _wait_for(records, opts["wait_for"])
    for text in opts["say"]:
        print(text, flush=True)
    for text in opts["err"]:
        print(text, file=sys.stderr, flush=True)
    if opts["linger"] > 0:
        deadline = time.monotonic() + opts["linger"]
        while not stop and time.monotonic() < deadline:
            time.sleep(0.01)  # the recorder is the child under test, not a test: polling is fine
    sys.exit(opts["exit"])


if __name__ == "__main__":
    main()
