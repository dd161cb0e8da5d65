"""A roslaunch file run natively on ROS 1, as roslaunch runs it, under mlaunch's supervision.

``description(path, args, environ, temp_dir)`` resolves the file as roslaunch does
(``mlaunch.ros1.config``) and returns the launch description that runs it:

1. a master (``rosmaster --core``) and roscore.xml's nodes (rosout) when none answers at
   ``ROS_MASTER_URI``, as roslaunch starts them;
2. the parameter server loaded as roslaunch loads it (``mlaunch.parts.ros1_params``: /run_id,
   ``clear_params``, then every parameter in one multicall);
3. when that succeeded, every node with roslaunch's command line (launch-prefix, the program,
   ``args`` split like a shell, remaps as ``from:=to``, ``__name:=``, ``__log:=``) and
   environment (``ROS_MASTER_URI``, ``ROS_NAMESPACE``, its ``<env>``), ``required``,
   ``respawn``/``respawn_delay`` and ``cwd`` (ROS_HOME, or the program's folder).

ROS 1's Python nodes run with the system's Python: mlaunch's own virtual environment is taken
out of their PATH, PYTHONPATH and VIRTUAL_ENV. Everything else is mlaunch's: labels, logs,
--status, ctl, no orphans.
"""

from __future__ import annotations

import os
import pickle
import shlex
import sys
import uuid
from collections.abc import Mapping
from typing import Any

from mlaunch.launch.action import Action
from mlaunch.launch.actions.execute_process import ExecuteProcess
from mlaunch.parts.ros1_environ import system_python_env
from mlaunch.plan.errors import LaunchFileError, UsageError
from mlaunch.ros1.actions import MappingWarning
from mlaunch.ros1.config import Config, Ros1Node, load
from mlaunch.ros1.lookup import catkin_find, package_finder

DEFAULT_MASTER = "http://localhost:11311/"
# Programs of older ROS 1 releases the seeds use -> what replaced them.
RENAMED = {
    ("robot_state_publisher", "state_publisher"): "robot_state_publisher",
    ("xacro", "xacro.py"): "xacro",
}


def wants_native(path: str, environ: Mapping[str, str]) -> bool:
    """A shell set up for ROS 1 (as a ROS 1 setup.bash leaves it) and a roslaunch file."""
    ros1_shell = environ.get("ROS_VERSION") == "1" and bool(environ.get("ROS_DISTRO"))
    return ros1_shell and bool(environ.get("ROS_MASTER_URI")) and is_roslaunch_file(path)


def is_roslaunch_file(path: str) -> bool:
    from mlaunch import readers

    return readers.frontend_for(path) == readers.FRONTENDS[".launch"]


def description(
    path: str, args: Mapping[str, str], environ: Mapping[str, str], temp_dir: str
) -> Any:
    """The launch description of a native ROS 1 run of ``path``."""
    from mlaunch.launch.launch_description import LaunchDescription

    env = dict(environ)
    config = load(path, args, environ=env, core=True)
    uri = env.get("ROS_MASTER_URI") or DEFAULT_MASTER
    host, port = master_address(uri)
    env["ROS_MASTER_URI"] = uri
    actions: list[Any] = [MappingWarning(w, path) for w in config.warnings]
    from mlaunch.parts.ros1_params import master_ready

    start_master = not master_ready(uri)
    if start_master and port_answers(host, port):
        # A master mlaunch started could not bind it: rosmaster waits for the port forever,
        # and the parameter loader for the master.
        raise UsageError(
            f"ROS_MASTER_URI={uri}: port {port} is held by a program that is not a ROS master"
            " (it does not answer the master's getPid); stop it, or set ROS_MASTER_URI to a"
            " free port (http://localhost:PORT/)"
        )
    run_id = str(uuid.uuid1())
    if start_master:
        actions.append(master_process(uri, env))
    loader = params_process(config, uri, run_id, temp_dir, env)
    actions.append(loader)
    actions += machines(config, path)
    for action in actions:
        action.origin = f"{os.path.abspath(path)}:1"
    nodes = [*(config.core_nodes if start_master else []), *config.nodes]
    finder = package_finder(path, env)
    processes: list[Any] = []
    started: list[Ros1Node] = []
    for number, node in enumerate(nodes, start=1):
        remote = is_remote(config, node)
        process, message = node_process(node, finder, env, f"{run_id}", number, remote)
        if message:
            actions.append(MappingWarning(message, node.origin))
        if process is not None:
            processes.append(process)
            started.append(node)
    from mlaunch.parts.ros1_print import DescribeNodes, NativeNodes

    note = NativeNodes(loader.origin, [p.native for p in processes], config.params, environ)
    for action in (DescribeNodes(note), after_loading(loader, processes)):
        action.origin = loader.origin
        actions.append(action)
    out = LaunchDescription(actions)
    out.__dict__[_RUN] = NativeRun(uri, tuple(started))
    return out


_RUN = "_mlaunch_ros1_run"


class NativeRun:
    """What a native ROS 1 run's description starts: its master's URI and the nodes it
    starts (those whose program was found), for ``mlaunch test``'s checks."""

    __slots__ = ("master_uri", "nodes")

    def __init__(self, master_uri: str, nodes: tuple[Ros1Node, ...]) -> None:
        self.master_uri = master_uri
        self.nodes = nodes


def native_run(description: object) -> NativeRun | None:
    """The NativeRun of a description ``description()`` made (None: any other)."""
    found = getattr(description, "__dict__", {}).get(_RUN)
    return found if isinstance(found, NativeRun) else None


def master_address(uri: str) -> tuple[str, int]:
    """The host and port of ``ROS_MASTER_URI``; a value that is not an http URL with a host is
    a usage error (was an internal error from the XML-RPC client)."""
    from urllib.parse import urlsplit

    why = ""
    try:
        parts = urlsplit(uri)
        if parts.hostname and parts.scheme in ("http", "https"):
            return parts.hostname, parts.port or 11311
    except ValueError as e:  # a port that is not a number, or out of range
        why = f" ({e})"
    raise UsageError(
        f"ROS_MASTER_URI={uri!r} is not a ROS master's address{why}: write it as"
        " http://HOST:PORT/ (such as http://localhost:11311/)"
    )


def port_answers(host: str, port: int) -> bool:
    """Whether something accepts TCP connections at ``host``:``port`` (within a second)."""
    import socket

    try:
        with socket.create_connection((host, port), timeout=1.0):
            return True
    except OSError:
        return False


def master_process(uri: str, env: dict[str, str]) -> Any:
    """``rosmaster --core -p PORT``, as roslaunch starts it."""
    import shutil

    program = shutil.which("rosmaster", path=env.get("PATH"))
    if program is None:
        raise LaunchFileError(
            f"no ROS master answers at {uri} and rosmaster is not installed (Debian:"
            " apt-get install python3-rosmaster; or start roscore first)"
        )
    from urllib.parse import urlparse

    port = str(urlparse(uri).port or 11311)
    return Ros1Process(
        cmd=[program, "--core", "-p", port, "-w", "3"],
        name="master",
        env=system_python_env(env),
        required=True,
        output="log",
    )


class ParamsLoader(ExecuteProcess):
    """The process that loads the parameter server (mlaunch.parts.ros1_params)."""

    def describe_short(self) -> str:
        return "roslaunch_params (the parameter server's loader)"


class Ros1Process(ExecuteProcess):
    """An ExecuteProcess for a ROS 1 program (the master, a node), stopped and set up as
    roslaunch does: its stop ladder is roslaunch's (SIGINT, SIGTERM after 15 s, SIGKILL 2 s
    later: ``_TIMEOUT_SIGINT`` and ``_TIMEOUT_SIGTERM`` of roslaunch's nodeprocess), and its
    environment is the one it is given, without what mlaunch adds for ROS 2 children (rcutils'
    line buffering). ``PYTHONUNBUFFERED`` stays: the program's output goes through mlaunch's
    pipe, where Python would hold it back."""

    RCUTILS = "RCUTILS_LOGGING_BUFFERED_STREAM"
    SIGINT_TIMEOUT = 15.0
    SIGTERM_TIMEOUT = 2.0

    native: Any = None  # the node as --print shows it (mlaunch.parts.ros1_print.NativeNode)

    def __init__(self, *, env: dict[str, str] | None = None, **kwargs: Any) -> None:
        kwargs.setdefault("sigterm_timeout", self.SIGINT_TIMEOUT)
        kwargs.setdefault("sigkill_timeout", self.SIGTERM_TIMEOUT)
        super().__init__(env=env, **kwargs)
        self._given_rcutils = env is not None and self.RCUTILS in env

    def _environment(self, ctx: Any) -> dict[str, str]:
        env = super()._environment(ctx)
        if not self._given_rcutils:
            env.pop(self.RCUTILS, None)
        return env


def machines(config: Config, path: str) -> list[Any]:
    """The file's ``<machine>``s as mlaunch's machines (docs/machines.md): the nodes that name
    one run there over ssh. ``default`` is already each node's machine (roslaunch's rule)."""
    from mlaunch.machines.actions import Machine
    from mlaunch.ros1.model import MACHINE_FIELDS

    out: list[Any] = []
    for name, found in config.machines.items():
        options = {k: found[a] for k, a in MACHINE_FIELDS if k != "default" and found.get(a)}
        out.append(Machine(name=name, address=found["address"], **options))
        if found.get("password"):
            note = f"<machine name={name!r} password> is ignored: mlaunch's ssh uses keys only"
            out.append(MappingWarning(note, f"{os.path.abspath(path)}:1"))
    return out


def params_process(config: Config, uri: str, run_id: str, temp_dir: str, env: Any) -> Any:

    job = {
        "master_uri": uri,
        "run_id": run_id,
        "clear_params": list(config.clear_params),
        "params": dict(config.params),
    }
    os.makedirs(temp_dir, exist_ok=True)
    job_file = os.path.join(temp_dir, f"ros1-params-{run_id}.pickle")
    with open(job_file, "wb") as f:
        pickle.dump(job, f)
    return ParamsLoader(
        cmd=[sys.executable, "-m", "mlaunch.parts.ros1_params", job_file],
        name="roslaunch_params",
        env=env,
        output="screen",
    )


def after_loading(loader: Any, processes: list[Any]) -> Any:
    """The nodes start once the parameter server is loaded (roslaunch's order); a failed load
    ends the run."""
    from mlaunch.launch.actions.register_event_handler import RegisterEventHandler
    from mlaunch.launch.event_handlers.on_process_exit import OnProcessExit

    return RegisterEventHandler(OnProcessExit(target_action=loader, on_exit=StartNodes(processes)))


class StartNodes:
    """The loader's exit: the nodes start when it loaded the parameter server, else the run
    ends with status 1 (roslaunch's order and status)."""

    def __init__(self, processes: list[Any]) -> None:
        self.processes = processes

    def __call__(self, event: Any, context: Any) -> list[Any]:
        if event.returncode != 0:
            return [FailedLoad()]
        return self.processes

    def describe(self) -> str:
        return (
            f"start the {len(self.processes)} node(s) above when it exited with status 0,"
            " else end the run with status 1"
        )


class FailedLoad(Action):
    """The parameter server could not be loaded: the run ends with exit status 1, as roslaunch
    ends then (a Shutdown, whose status is 0, hid the failure)."""

    REASON = "the ROS 1 parameter server could not be loaded"

    def execute(self, context: Any) -> None:
        from mlaunch.launch.events.shutdown import Shutdown as ShutdownEvent
        from mlaunch.plan.errors import EXIT_FAILURE
        from mlaunch.plan.steps import RequestShutdown

        step = RequestShutdown(origin=self.origin, reason=self.REASON, status=EXIT_FAILURE)
        context.planner.emit(ShutdownEvent(reason=self.REASON), step)


def node_process(
    node: Ros1Node, finder: Any, env: dict[str, str], run_id: str, number: int, remote: bool
) -> tuple[Any, str]:
    """The node's process as roslaunch starts it (its ``number``-th), and a warning: why it
    cannot start (in roslaunch's words), or what it runs instead of an old name."""

    program, note = find_node(node, finder, env)
    if program is None:
        return None, f"cannot launch node of type [{node.package}/{node.type}]: {note}"
    log_dir = os.path.join(ros_log_dir(env), run_id)
    os.makedirs(log_dir, exist_ok=True)  # roslaunch makes it (rosout writes its log there)
    process_name = f"{node.full_name.lstrip('/')}-{number}"
    argv = [
        *shlex.split(node.launch_prefix or ""),
        program,
        *shlex.split(node.args),
        *(f"{src}:={dst}" for src, dst in node.remaps),
        f"__name:={node.name}",
    ]
    # roslaunch sets the node's log file itself: a __log:= of the file is dropped
    argv = [a for a in argv if not a.startswith("__log:=")]
    argv.append(f"__log:={os.path.join(log_dir, process_name.replace('/', '-') + '.log')}")
    node_env = system_python_env(env)
    node_env.pop("ROS_NAMESPACE", None)
    namespace = node.namespace.rstrip("/")
    if namespace:
        node_env["ROS_NAMESPACE"] = namespace
    node_env.update({str(k): str(v) for k, v in node.env})
    cwd: str | None = os.path.dirname(program) if node.cwd == "node" else ros_home(env)
    env_arg: dict[str, str] | None = node_env
    if remote:
        # On another computer: its own login environment and home, plus what roslaunch gives
        # a node there (the master, the namespace, the node's <env>), set by env(1) on it.
        cwd, env_arg = None, None
        argv = [*remote_env(node, env["ROS_MASTER_URI"]), *argv]
    else:
        os.makedirs(str(cwd), exist_ok=True)
    process = Ros1Process(
        cmd=argv,
        name=node.name,
        env=env_arg,
        cwd=cwd,
        machine=node.machine if remote else None,
        output="screen" if node.output == "screen" else "log",
        respawn=node.respawn,
        respawn_delay=node.respawn_delay or None,
        required=node.required,
    )
    process.origin = node.origin
    # roslaunch's number for the process (its __log:= file's), not mlaunch's count, which
    # also counts the master and the parameter loader and skips the nodes that cannot start.
    process.exact_label = f"{node.name}-{number}"
    from mlaunch.parts.ros1_print import NativeNode

    stop = (Ros1Process.SIGINT_TIMEOUT, Ros1Process.SIGTERM_TIMEOUT)
    process.native = NativeNode(node, argv, env_arg, cwd, stop)
    return process, note


def is_remote(config: Config, node: Ros1Node) -> bool:
    """Whether the node runs on another computer: a machine that is this one runs it here,
    as roslaunch did (the address is local and the user is ours or not given)."""
    from mlaunch.plan.machine import is_local

    machine = config.machines.get(node.machine or "")
    return machine is not None and not is_local(machine["address"], machine.get("user") or None)


def remote_env(node: Ros1Node, uri: str) -> list[str]:
    """``env`` setting a remote node's ROS 1 environment before its command line."""
    namespace = node.namespace.rstrip("/")
    scope = [f"ROS_NAMESPACE={namespace}"] if namespace else ["-u", "ROS_NAMESPACE"]
    return ["env", *scope, f"ROS_MASTER_URI={uri}", *(f"{k}={v}" for k, v in node.env)]


def find_node(node: Ros1Node, finder: Any, environ: Mapping[str, str]) -> tuple[str | None, str]:
    """roslib's find_node: the executable ``type`` where catkin_find looks (a workspace's
    ``lib/PKG``, ``share/PKG``, source spaces), then in the package's folder; the first."""
    kind, note = node.type, ""
    renamed = RENAMED.get((node.package, kind))
    if renamed is not None:
        note = (
            f"{node.package}/{kind} is the name of an older ROS 1 release:"
            f" running {node.package}/{renamed}, which replaced it"
        )
        kind = renamed
    try:
        folder = finder(node.package)
    except LaunchFileError as e:
        return None, str(e)
    for root in (*catkin_find(node.package, environ), folder):
        for base, dirs, files in os.walk(root, followlinks=True):
            dirs[:] = [d for d in dirs if not d.startswith(".")]
            if kind in files and is_executable(os.path.join(base, kind)):
                return os.path.abspath(os.path.join(base, kind)), note
    return None, f"Cannot locate node of type [{kind}] in package [{node.package}]"


def is_executable(path: str) -> bool:
    """roslib's test: readable and executable by its owner."""
    import stat

    try:
        mode = os.stat(path).st_mode
    except OSError:
        return False
    wanted = stat.S_IRUSR | stat.S_IXUSR
    return mode & wanted == wanted


def ros_home(env: Mapping[str, str]) -> str:
    return env.get("ROS_HOME") or os.path.join(env.get("HOME") or os.path.expanduser("~"), ".ros")


def ros_log_dir(env: Mapping[str, str]) -> str:
    return env.get("ROS_LOG_DIR") or os.path.join(ros_home(env), "log")
