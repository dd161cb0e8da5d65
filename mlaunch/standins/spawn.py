"""Spawner stand-in: hands a robot model to the simulator stand-in, like spawn_entity.py / create.

Run as ``python -m mlaunch.standins.spawn spawn_entity.py ARGS...`` (gazebo_ros) or
``python -m mlaunch.standins.spawn create ARGS...`` (ros_gz_sim), ARGS being what the real
program got, ROS arguments included. It reads the model (-file, -string, -stdin or the first
message on -topic, which robot_state_publisher latches), checks it is a URDF, publishes a spawn
request on ``/mlaunch_sim/spawn`` and waits for the simulator's answer on
``/mlaunch_sim/spawned``. Exit 0 once spawned; otherwise one line saying why and exit 1
(2 for a bad command line).

rclpy and the message packages are imported inside main() only.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
import uuid
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, NoReturn

from mlaunch.plan.errors import StandinError
from mlaunch.standins.common import StopFlag, install_stop_flag, latched
from mlaunch.standins.sim import SPAWN_TOPIC, SPAWNED_TOPIC

DEFAULT_TIMEOUT = 30.0  # spawn_entity.py's -timeout default
FLAVORS = {"spawn_entity.py": "gazebo_ros", "spawn_entity": "gazebo_ros", "create": "ros_gz_sim"}
NODE_NAMES = {"gazebo_ros": "spawn_entity", "ros_gz_sim": "ros_gz_sim"}
SOURCES = ("file", "topic", "string", "stdin", "database", "param")


class SpawnError(StandinError):
    """Why the model was not spawned; printed as one line."""

    def __init__(self, message: str, exit_code: int = 1):
        super().__init__(message)
        self.exit_code = exit_code


# ---------------------------------------------------------------- command line


@dataclass
class SpawnOptions:
    """A spawn command line, either flavor, in one shape."""

    flavor: str  # gazebo_ros or ros_gz_sim
    program: str
    name: str
    source: str  # one of SOURCES
    value: str = ""
    pose: tuple[float, float, float, float, float, float] = (0.0,) * 6
    timeout: float = DEFAULT_TIMEOUT
    sim_timeout: float | None = None  # -spawn_service_timeout when given
    robot_namespace: str | None = None
    allow_renaming: bool = False
    ignored: list[str] = field(default_factory=list)


class _Parser(argparse.ArgumentParser):
    """argparse that raises SpawnError instead of printing usage and exiting."""

    def error(self, message: str) -> NoReturn:
        raise SpawnError(f"{self.prog}: {message}", exit_code=2)


def _pose_options(p: argparse.ArgumentParser, prefixes: Sequence[str]) -> None:
    for key in ("x", "y", "z", "R", "P", "Y"):
        p.add_argument(
            *(f"{pre}{key}" for pre in prefixes), type=float, default=0.0, dest=f"pose_{key}"
        )


def _gazebo_ros_parser() -> argparse.ArgumentParser:
    p = _Parser(prog="spawn_entity.py", add_help=False, allow_abbrev=False)
    source = p.add_mutually_exclusive_group(required=True)
    for name in ("file", "topic", "string", "database", "param"):
        source.add_argument(f"-{name}", dest=f"source_{name}")
    source.add_argument("-stdin", action="store_true", dest="source_stdin")
    p.add_argument("-entity", required=True)
    p.add_argument("-timeout", type=float, default=DEFAULT_TIMEOUT)
    p.add_argument("-spawn_service_timeout", type=float)
    p.add_argument("-robot_namespace")
    for flag in ("-reference_frame", "-gazebo_namespace", "-wait"):
        p.add_argument(flag, dest=f"ignored_{flag[1:]}")
    for flag in ("-unpause", "-package_to_model", "-b", "-bond"):
        p.add_argument(flag, action="store_true", dest=f"ignored_{flag[1:]}")
    _pose_options(p, ("-",))
    return p


def _ros_gz_parser() -> argparse.ArgumentParser:
    # gflags accepts -name, --name and -name=value alike.
    p = _Parser(prog="create", add_help=False, allow_abbrev=False)
    source = p.add_mutually_exclusive_group(required=True)
    for name in ("file", "topic", "string", "param"):
        source.add_argument(f"-{name}", f"--{name}", dest=f"source_{name}")
    p.add_argument("-name", "--name", dest="entity", required=True)
    p.add_argument("-allow_renaming", "--allow_renaming", nargs="?", const="true", default="false")
    p.add_argument("-timeout", "--timeout", type=float, default=DEFAULT_TIMEOUT)
    p.add_argument("-world", "--world", dest="ignored_world")
    _pose_options(p, ("-", "--"))
    return p


def parse_spawn_args(args: Sequence[str]) -> SpawnOptions:
    """Read ``spawn_entity.py ARGS`` or ``create ARGS`` (ROS arguments already removed)."""
    if not args or Path(args[0]).name not in FLAVORS:
        first = args[0] if args else "nothing"
        raise SpawnError(
            f"spawn: the first argument names the program, got {first!r}; "
            f"expected one of {', '.join(FLAVORS)}",
            exit_code=2,
        )
    program = Path(args[0]).name
    flavor = FLAVORS[program]
    parser = _gazebo_ros_parser() if flavor == "gazebo_ros" else _ros_gz_parser()
    known = {s for action in parser._actions for s in action.option_strings}
    # Checked before argparse, which would read -bogus as -b with the value "ogus".
    unknown = [a for a in args[1:] if _looks_like_option(a) and a.split("=", 1)[0] not in known]
    if not unknown:
        namespace, unknown = parser.parse_known_args(list(args[1:]))
    if unknown:
        raise SpawnError(
            f"{program}: unknown option {unknown[0]!r}; valid options are: "
            + " ".join(sorted(known)),
            exit_code=2,
        )
    options = _options_from(namespace, flavor, program)
    _check_options(options)
    return options


def _looks_like_option(token: str) -> bool:
    if not token.startswith("-") or token == "-":
        return False
    try:
        float(token)
    except ValueError:
        return True
    return False  # a negative number, e.g. -x -1.5


def _options_from(ns: argparse.Namespace, flavor: str, program: str) -> SpawnOptions:
    source = next(s for s in SOURCES if getattr(ns, f"source_{s}", None) not in (None, False))
    value = getattr(ns, f"source_{source}")
    pose = (ns.pose_x, ns.pose_y, ns.pose_z, ns.pose_R, ns.pose_P, ns.pose_Y)
    options = SpawnOptions(
        flavor=flavor,
        program=program,
        name=ns.entity,
        source=source,
        value="" if value is True else str(value),
        pose=pose,
        timeout=ns.timeout,
        sim_timeout=getattr(ns, "spawn_service_timeout", None),
        robot_namespace=getattr(ns, "robot_namespace", None),
        allow_renaming=_gflag_bool(
            program, "allow_renaming", getattr(ns, "allow_renaming", "false")
        ),
    )
    for key, val in sorted(vars(ns).items()):
        if key.startswith("ignored_") and val:
            options.ignored.append(
                f"-{key.removeprefix('ignored_')}" + ("" if val is True else f" {val}")
            )
    return options


def _gflag_bool(program: str, name: str, text: str) -> bool:
    value = text.strip().lower()
    if value in ("true", "1", "yes"):
        return True
    if value in ("false", "0", "no"):
        return False
    raise SpawnError(f"{program}: -{name} is {text!r}; expected true or false", exit_code=2)


def _check_options(options: SpawnOptions) -> None:
    program = options.program
    if not options.name:
        raise SpawnError(
            f"{program}: the entity name is empty; give -entity/-name NAME", exit_code=2
        )
    for what, value in (
        ("-timeout", options.timeout),
        ("-spawn_service_timeout", options.sim_timeout),
    ):
        if value is not None and not value > 0:
            raise SpawnError(f"{program}: {what} is {value!r}; expected seconds > 0", exit_code=2)
    if options.source == "database":
        raise SpawnError(
            f"{program}: -database {options.value!r}: the Gazebo model database is not "
            "available to the stand-in; give the model with -file, -string or -topic"
        )
    if options.source == "param":
        raise SpawnError(
            f"{program}: -param {options.value!r} is not supported by the stand-in; "
            "use -topic robot_description"
        )


# ---------------------------------------------------------------- the model text


def read_model(options: SpawnOptions, read_stdin: Callable[[], str] = sys.stdin.read) -> str | None:
    """The model XML for -file/-string/-stdin; None for -topic (it comes from ROS)."""
    if options.source == "string":
        return options.value
    if options.source == "stdin":
        return read_stdin()
    if options.source == "file":
        path = Path(options.value)
        try:
            return path.read_text(encoding="utf-8")
        except FileNotFoundError:
            raise SpawnError(f"{options.program}: -file {options.value!r} does not exist") from None
        except (OSError, UnicodeDecodeError) as exc:
            raise SpawnError(
                f"{options.program}: -file {options.value!r} cannot be read: {exc}"
            ) from None
    return None


def check_model(options: SpawnOptions, xml: str) -> str:
    """Refuse what the simulator would refuse, before bothering it; the model as URDF.

    An SDF model (``create -file model.sdf``) is written as the URDF robot it describes
    (mlaunch.standins.sdf_model), with a warning for each part that does not carry over.
    """
    from mlaunch.standins.sdf_model import SdfError, is_sdf, sdf_to_urdf
    from mlaunch.standins.urdf import UrdfError, parse_urdf

    if is_sdf(xml):
        source = options.value if options.source == "file" else "the SDF model"
        try:
            translation = sdf_to_urdf(xml, source)
        except SdfError as exc:
            raise SpawnError(f"{options.program}: bad SDF for {options.name!r}: {exc}") from None
        for note in translation.notes:
            print(f"{options.program}: warning: {note}", file=sys.stderr, flush=True)
        xml = translation.urdf
    try:
        parse_urdf(xml)
    except UrdfError as exc:
        raise SpawnError(f"{options.program}: bad URDF for {options.name!r}: {exc}") from None
    return xml


def spawn_request(options: SpawnOptions, xml: str, request_id: str, node_namespace: str) -> str:
    """The JSON spawn request for the simulator."""
    x, y, z, roll, pitch, yaw = options.pose
    request: dict[str, object] = {
        "name": options.name,
        "x": x,
        "y": y,
        "z": z,
        "roll": roll,
        "pitch": pitch,
        "yaw": yaw,
        "urdf": xml,
        "id": request_id,
    }
    # spawn_entity.py defaults -robot_namespace to its own namespace and pushes it into every
    # plugin; at the root namespace that changes nothing, so only send a real one.
    namespace = options.robot_namespace
    if namespace is None and options.flavor == "gazebo_ros" and node_namespace not in ("", "/"):
        namespace = node_namespace
    if namespace:
        request["robot_namespace"] = namespace
    if options.allow_renaming:
        request["allow_renaming"] = True
    return json.dumps(request)


# ---------------------------------------------------------------- ROS side


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point; returns the exit status."""
    stop = install_stop_flag()
    argv = list(sys.argv if argv is None else argv)
    try:
        return _run(argv, stop)
    except SpawnError as exc:
        print(f"{exc}", file=sys.stderr, flush=True)
        return exc.exit_code
    except KeyboardInterrupt:
        return 130


def _run(argv: list[str], stop: StopFlag) -> int:
    from rclpy.utilities import remove_ros_args

    options = parse_spawn_args(remove_ros_args(argv)[1:])
    for note in options.ignored:
        print(
            f"{options.program}: warning: {note} is ignored by the stand-in",
            file=sys.stderr,
            flush=True,
        )
    xml = read_model(options)
    if xml is not None:
        xml = check_model(options, xml)
    return _spawn(argv, options, xml, stop)


def _spawn(argv: list[str], options: SpawnOptions, xml: str | None, stop: StopFlag) -> int:
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.signals import SignalHandlerOptions
    from rclpy.utilities import try_shutdown

    try:
        rclpy.init(args=argv, signal_handler_options=SignalHandlerOptions.NO)
    except Exception as exc:  # rclpy raises its own types for bad --ros-args
        raise SpawnError(f"{options.program}: cannot start ROS: {exc}") from None
    node = None
    try:
        node = rclpy.create_node(NODE_NAMES[options.flavor])
        executor = SingleThreadedExecutor()
        executor.add_node(node)
        waiter = _Waiter(executor, stop, options.program)
        if xml is None:
            xml = check_model(options, _model_from_topic(node, waiter, options))
        name = _hand_over(node, waiter, options, xml)
        print(f"{options.program}: spawned entity {name!r}", flush=True)
        return 0
    finally:
        if node is not None:
            node.destroy_node()
        try_shutdown()


@dataclass
class _Waiter:
    """Spins the executor until a condition holds, the deadline passes or a signal arrives."""

    executor: Any
    stop: StopFlag
    program: str

    def until(self, done: Callable[[], bool], timeout: float) -> bool:
        """True when ``done()`` became true within ``timeout`` seconds."""
        deadline = time.monotonic() + timeout
        while not done():
            if self.stop.requested:
                raise SpawnError(
                    f"{self.program}: interrupted before the entity was spawned", exit_code=130
                )
            left = deadline - time.monotonic()
            if left <= 0:
                return False
            self.executor.spin_once(timeout_sec=min(left, 0.05))
        return True


def _model_from_topic(node: Any, waiter: _Waiter, options: SpawnOptions) -> str:
    """The first message on -topic (robot_state_publisher latches robot_description)."""
    from std_msgs.msg import String

    received: list[str] = []
    sub = node.create_subscription(
        String, options.value, lambda msg: received.append(msg.data), latched(10)
    )
    topic = sub.topic_name
    if not waiter.until(lambda: bool(received), options.timeout):
        publishers = node.count_publishers(topic)
        why = (
            "nothing publishes it"
            if publishers == 0
            else f"{publishers} publisher(s) but no message arrived"
        )
        raise SpawnError(
            f"{options.program}: timed out after {options.timeout:g} s "
            f"waiting for the model on {topic} ({why})"
        )
    node.destroy_subscription(sub)
    return received[0]


def _hand_over(node: Any, waiter: _Waiter, options: SpawnOptions, xml: str) -> str:
    """Send the spawn request and wait for the simulator's answer; return the spawned name."""
    from std_msgs.msg import String

    request_id = uuid.uuid4().hex
    replies: list[dict[str, Any]] = []

    def on_reply(msg: Any) -> None:
        try:
            reply = json.loads(msg.data)
        except json.JSONDecodeError:
            return
        if isinstance(reply, dict) and reply.get("id") == request_id:
            replies.append(reply)

    node.create_subscription(String, SPAWNED_TOPIC, on_reply, latched(10))
    publisher = node.create_publisher(String, SPAWN_TOPIC, latched(10))
    publisher.publish(String(data=spawn_request(options, xml, request_id, node.get_namespace())))
    timeout = options.sim_timeout if options.sim_timeout is not None else options.timeout
    if not waiter.until(lambda: bool(replies), timeout):
        found = publisher.get_subscription_count()
        why = "no simulator is running" if found == 0 else "the simulator did not answer"
        raise SpawnError(
            f"{options.program}: timed out after {timeout:g} s spawning {options.name!r}: "
            f"{why} (listening on {SPAWN_TOPIC})"
        )
    reply = replies[0]
    if not reply.get("ok"):
        raise SpawnError(
            f"{options.program}: the simulator refused {options.name!r}: "
            f"{reply.get('error') or 'no reason given'}"
        )
    return str(reply.get("name") or options.name)


if __name__ == "__main__":
    sys.exit(main())
