"""Simulator stand-in: a headless, deterministic 2D Gazebo for launch files that start one.

Run as ``python -m mlaunch.standins.sim ARGS...`` with the arguments ``gazebo``, ``gzserver``,
``gz sim`` or ``ign gazebo`` would have got. It loads the SDF world's static shapes, publishes
/clock, takes robots from the spawner stand-in (topic protocol below), drives them from their
diff-drive plugin's cmd_vel topic and publishes odometry, joint states, laser scans and IMU data
on the topics their ``<gazebo>`` plugin blocks name.

The world's shapes are published for the viewer on ``/mlaunch_sim/world`` (world_topic.py).
Spawn protocol (both topics reliable + transient_local, depth 10, std_msgs/String of JSON):
``/mlaunch_sim/spawn`` takes ``{"name", "x", "y", "z", "roll", "pitch", "yaw", "urdf"}`` plus
optional ``"id"``, ``"robot_namespace"`` and ``"allow_renaming"``; ``/mlaunch_sim/spawned``
answers ``{"name", "ok", "error"}`` (and the request's ``"id"``).

rclpy and the message packages are imported inside main() only.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, NoReturn

from mlaunch.plan.errors import StandinError
from mlaunch.standins.common import StopFlag, install_stop_flag, latched
from mlaunch.standins.diffdrive import Pose2D, describe_model
from mlaunch.standins.gz_bridge import BRIDGES_TOPIC
from mlaunch.standins.plugins import ModelError
from mlaunch.standins.sim_topics import (
    PROG,
    Output,
    make_outputs,
    make_publisher,
    make_subscription,
    say,
    subscribe_cmd_vel,
    tf_support,
    warn,
)
from mlaunch.standins.simulation import STEP_NS, Schedule, SimRobot, Simulation
from mlaunch.standins.spawn_request import SpawnRequest, free_name, parse_spawn_request
from mlaunch.standins.world import RESOURCE_PATH_VARS, World, WorldError, load_world
from mlaunch.standins.world_topic import WORLD_TOPIC, world_message

SPAWN_TOPIC = "/mlaunch_sim/spawn"
SPAWNED_TOPIC = "/mlaunch_sim/spawned"
CLOCK_RATE = 100.0  # /clock messages per second of sim time
# Falling further behind real time than this (a suspended process, a slow machine) is not
# caught up in a burst: the simulation just runs slower than asked, as Gazebo does.
MAX_LAG_S = 0.25
EMPTY_WORLDS = ("empty.world", "empty.sdf")
# Gazebo system plugins whose ROS side the stand-in itself provides (/clock, spawning).
PROVIDED_PLUGINS = ("libgazebo_ros_init.so", "libgazebo_ros_factory.so")
STEPS_BETWEEN_SPINS = 10  # at most this many steps back to back before serving callbacks


class SimUsageError(StandinError):
    """A command line the simulator cannot run with."""


# ---------------------------------------------------------------- command line


@dataclass
class SimOptions:
    """What the simulator takes from a Gazebo command line."""

    flavor: str  # "gazebo" (classic gazebo/gzserver) or "gz" (gz sim / ign gazebo)
    world: str | None = None
    seed: int | None = None
    ignored: list[str] = field(default_factory=list)


def _classic_parser() -> argparse.ArgumentParser:
    p = _Parser(prog="gazebo", add_help=False, allow_abbrev=False)
    p.add_argument("--verbose", action="store_true")
    p.add_argument("--seed", type=int)
    for flag in (
        "-u",
        "--pause",
        "-r",
        "--record",
        "--minimal_comms",
        "--lockstep",
        "-v",
        "--version",
    ):
        p.add_argument(flag, action="store_true", dest=f"ignored_{flag.lstrip('-')}")
    for pair in (("-s", "--server-plugin"), ("-g", "--gui-plugin")):
        p.add_argument(*pair, action="append", default=[], dest=f"plugins_{pair[0][1:]}")
    valued: list[tuple[str, ...]] = [("-e", "--physics"), ("-p", "--play"), ("-o", "--profile")]
    valued += [(f,) for f in ("--iters", "--record_path", "--record_period", "--record_filter")]
    valued.append(("--record_encoding",))
    for flags in valued:
        p.add_argument(*flags, dest=f"ignored_{flags[-1].lstrip('-')}")
    p.add_argument("positional", nargs="*")
    return p


def _gz_parser() -> argparse.ArgumentParser:
    p = _Parser(prog="gz sim", add_help=False, allow_abbrev=False)
    p.add_argument("--verbosity", type=int)
    p.add_argument("--seed", type=int)
    p.add_argument("-r", action="store_true", dest="run")
    # -s (the server alone) is what the stand-in is: nothing to say about it.
    p.add_argument("-s", action="store_true", dest="server")
    for flag in ("-g", "--levels", "--record", "--headless-rendering", "--wait-for-assets"):
        p.add_argument(flag, action="store_true", dest=f"ignored_{flag.lstrip('-')}")
    for flag in ("-z", "--iterations", "--network-role", "--network-secondaries", "--record-path",
                 "--playback", "--initial-sim-time", "--render-engine", "--render-engine-gui",
                 "--render-engine-server", "--physics-engine", "--gui-config"):  # fmt: skip
        p.add_argument(flag, dest=f"ignored_{flag.lstrip('-')}")
    p.add_argument("positional", nargs="*")
    return p


class _Parser(argparse.ArgumentParser):
    """argparse that raises instead of printing usage and exiting."""

    def error(self, message: str) -> NoReturn:
        raise SimUsageError(message)


def _flavor(args: list[str]) -> tuple[str, list[str]]:
    """Decide classic vs gz from the leading words, and drop them.

    The stand-in gets what the real program got: ``gz sim -r w.sdf`` arrives as
    ``sim -r w.sdf`` and ``ign gazebo w.sdf`` as ``gazebo w.sdf``; a leading program name
    (``gz``, ``ign``, ``gzserver``) is accepted too.
    """
    rest = list(args)
    if rest and rest[0] in ("gz", "ign"):
        rest.pop(0)
        if rest and rest[0] in ("sim", "gazebo"):
            rest.pop(0)
        return "gz", rest
    if rest and rest[0] in ("sim", "gazebo"):
        return "gz", rest[1:]
    if rest and rest[0] == "gzserver":
        rest.pop(0)
    return "gazebo", rest


def parse_sim_args(args: Sequence[str]) -> SimOptions:
    """Read a Gazebo command line (ROS arguments already removed) into SimOptions."""
    flavor, rest = _flavor(list(args))
    if flavor == "gz":
        rest = _gz_verbosity(rest)
    parser = _classic_parser() if flavor == "gazebo" else _gz_parser()
    namespace, unknown = parser.parse_known_args(rest)
    options = SimOptions(flavor=flavor, seed=namespace.seed)
    for token in unknown:
        options.ignored.append(f"unknown option {token}")
    for key, value in sorted(vars(namespace).items()):
        if key.startswith("plugins_"):  # -s / -g LIB, repeated
            flag = key.removeprefix("plugins_")
            libs = [lib for lib in value if Path(lib).name not in PROVIDED_PLUGINS]
            options.ignored.extend(f"-{flag} {lib}" for lib in libs)
        elif key.startswith("ignored_") and value:
            flag = key.removeprefix("ignored_")
            shown = value if isinstance(value, list) else ([] if value is True else [value])
            options.ignored.append(
                " ".join([f"-{'-' if len(flag) > 1 else ''}{flag}", *map(str, shown)])
            )
    for token in namespace.positional:
        if token.endswith((".world", ".sdf")) and options.world is None:
            options.world = token
        else:
            options.ignored.append(f"argument {token!r}")
    if flavor == "gz" and not namespace.run:
        options.ignored.append("missing -r (gz sim would start paused; the stand-in runs at once)")
    return options


def _gz_verbosity(tokens: list[str]) -> list[str]:
    """``-v 4`` / ``-v`` / ``--verbose 4`` into ``--verbosity=N`` so -v never eats the world."""
    out: list[str] = []
    i = 0
    while i < len(tokens):
        token = tokens[i]
        if token in ("-v", "--verbose"):
            level = "1"
            if i + 1 < len(tokens) and tokens[i + 1].isdigit():
                level = tokens[i + 1]
                i += 1
            out.append(f"--verbosity={level}")
        elif token.startswith("-v") and token[2:].isdigit():
            out.append(f"--verbosity={token[2:]}")
        else:
            out.append(token)
        i += 1
    return out


def find_world(name: str, environ: Mapping[str, str]) -> Path | None:
    """The world file ``name`` refers to: as given, else under Gazebo's resource paths."""
    path = Path(name)
    if path.is_file() or path.is_absolute():
        return path if path.is_file() else None
    for var in RESOURCE_PATH_VARS:
        for directory in environ.get(var, "").split(os.pathsep):
            for candidate in (Path(directory) / name, Path(directory) / "worlds" / name):
                if directory and candidate.is_file():
                    return candidate
    return None


def open_world(options: SimOptions, environ: Mapping[str, str]) -> World:
    """Load the world the options name; no world, or Gazebo's stock empty world, is empty."""
    if options.world is None:
        return World(source="<no world file: empty world>")
    found = find_world(options.world, environ)
    if found is None:
        if Path(options.world).name in EMPTY_WORLDS:
            return World(name="default", source=f"{options.world} (stock empty world)")
        raise WorldError(
            "world file does not exist (looked in the current directory and "
            f"${', $'.join(RESOURCE_PATH_VARS)})",
            where=options.world,
        )
    return load_world(found, environ)


# ---------------------------------------------------------------- ROS side


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point: parse the Gazebo command line, load the world, serve until signalled."""
    stop = install_stop_flag()
    argv = list(sys.argv if argv is None else argv)
    try:
        return _run(argv, stop)
    except KeyboardInterrupt:  # a signal that raced our handler installation
        return 0


def _run(argv: list[str], stop: StopFlag) -> int:
    from rclpy.utilities import remove_ros_args

    try:
        options = parse_sim_args(remove_ros_args(argv)[1:])
    except SimUsageError as exc:
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        return 2
    if options.ignored:
        warn(f"ignored by the stand-in: {'; '.join(options.ignored)}")
    try:
        world = open_world(options, os.environ)
    except WorldError as exc:
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        return 1
    for note in world.warnings:
        warn(note)
    if stop.requested:
        return 0
    return _serve(argv, options, world, stop)


def _serve(argv: list[str], options: SimOptions, world: World, stop: StopFlag) -> int:
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.signals import SignalHandlerOptions
    from rclpy.utilities import try_shutdown

    try:
        rclpy.init(args=argv, signal_handler_options=SignalHandlerOptions.NO)
    except Exception as exc:  # rclpy raises its own types for bad --ros-args
        print(f"{PROG}: error: cannot start ROS: {exc}", file=sys.stderr)
        return 1
    node = None
    try:
        node = rclpy.create_node("gazebo")
        _default_sim_time(node)
        _ignore_own_clock(node)
        seed = int(
            _number_param(
                node, "seed", options.seed if options.seed is not None else 0, integer=True
            )
        )
        rtf = _real_time_factor(node)
        clock_rate = _number_param(node, "publish_rate", CLOCK_RATE)
        sim = Simulation(world, seed)
        bridge = RosBridge(node, sim, clock_rate)
        say(world.summary())
        say(f"running headless at real-time factor {rtf:g}, step {STEP_NS / 1e6:g} ms, seed {seed}")
        executor = SingleThreadedExecutor()
        executor.add_node(node)
        _loop(sim, bridge, executor, rtf, stop)
        return 0
    except ValueError as exc:
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        return 1
    finally:
        if node is not None:
            node.destroy_node()
        try_shutdown()


def _default_sim_time(node: Any) -> None:
    """use_sim_time is true unless the command line says otherwise, as gazebo_ros's nodes.

    The simulator is the clock: Gazebo's own ROS nodes run on sim time by default, and a launch
    file never passes parameters to an ExecuteProcess, so this is what makes every node of a
    simulated launch agree on the clock.
    """
    from rclpy.parameter import Parameter

    given = getattr(node, "_parameter_overrides", {})
    if "use_sim_time" not in given:
        node.set_parameters([Parameter("use_sim_time", Parameter.Type.BOOL, True)])


def _ignore_own_clock(node: Any) -> None:
    """Keep use_sim_time as given, but never subscribe the simulator to its own /clock.

    The parameter is accepted (launch files set it on every node), yet the simulator is the
    clock: with it on, rclpy would feed every /clock message back into this process, doubling
    the executor's wake-ups for nothing. rclpy has no public switch; TimeSource's is used.
    """
    time_source = getattr(node, "_time_source", None)
    if time_source is not None and hasattr(time_source, "ros_time_is_active"):
        time_source.ros_time_is_active = False


def _number_param(node: Any, name: str, default: float, integer: bool = False) -> float:
    """Declare a numeric parameter that accepts ints and doubles alike (-p x:=2 or x:=2.0)."""
    from rcl_interfaces.msg import ParameterDescriptor

    value = node.declare_parameter(name, default, ParameterDescriptor(dynamic_typing=True)).value
    if (
        isinstance(value, bool)
        or not isinstance(value, int | float)
        or (integer and value != int(value))
    ):
        kind = "an integer" if integer else "a number"
        raise ValueError(f"parameter {name} is {value!r}; expected {kind}")
    return float(value)


def _real_time_factor(node: Any) -> float:
    env = os.environ.get("MLAUNCH_SIM_RTF", "").strip()
    default = 1.0
    if env:
        try:
            default = float(env)
        except ValueError:
            raise ValueError(
                f"MLAUNCH_SIM_RTF is {env!r}; expected a number > 0 (1 = real time)"
            ) from None
    rtf = _number_param(node, "real_time_factor", default)
    if not math.isfinite(rtf) or rtf <= 0:
        raise ValueError(f"real_time_factor is {rtf!r}; expected a number > 0 (1 = real time)")
    return rtf


def _loop(sim: Simulation, bridge: RosBridge, executor: Any, rtf: float, stop: StopFlag) -> None:
    """Step sim time in lockstep with wall time / rtf; serve callbacks in between."""
    wall_step = sim.step_ns / 1e9 / rtf
    next_wall = time.monotonic()
    bridge.publish_due()
    unserved = 0
    while not stop.requested:
        now = time.monotonic()
        if now >= next_wall and unserved < STEPS_BETWEEN_SPINS:
            if now - next_wall > MAX_LAG_S:
                next_wall = now
            sim.step()
            bridge.publish_due()
            next_wall += wall_step
            unserved += 1
            continue
        # Behind schedule (a high real-time factor) callbacks still get a turn now and then.
        executor.spin_once(timeout_sec=max(0.0, next_wall - now))
        unserved = 0


class RosBridge:
    """Publishers, subscriptions and reused messages around one Simulation."""

    def __init__(self, node: Any, sim: Simulation, clock_rate: float):
        from rclpy.qos import QoSProfile, ReliabilityPolicy
        from rosgraph_msgs.msg import Clock
        from std_msgs.msg import String

        self.node = node
        self.sim = sim
        self.sensor_qos = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)
        latched_10 = latched(10)
        self.clock_msg = Clock()
        self.clock_pub = make_publisher(node, Clock, "/clock", self.sensor_qos)
        self.clock_schedule = Schedule.every(clock_rate, 0)
        self.String = String
        self.spawned_pub = make_publisher(node, String, SPAWNED_TOPIC, latched_10)
        make_subscription(node, String, SPAWN_TOPIC, self.on_spawn, latched_10)
        self.outputs: list[Output] = []
        self.answered: dict[str, str] = {}  # request id -> reply
        self.tf = tf_support()
        # The world for the viewer: latched, and only the newest one matters.
        self.world_pub = make_publisher(node, String, WORLD_TOPIC, latched())
        # cmd_vel subscriptions by topic, and the ROS types bridges announce for gz topics.
        self.commands: dict[str, tuple[SimRobot, Any, bool]] = {}
        self.bridged_types: dict[str, str] = {}
        make_subscription(node, String, BRIDGES_TOPIC, self.on_bridges, latched(10))
        self.run = f"{os.getpid()}-{os.urandom(4).hex()}"  # this start, for the viewer
        self.publish_world()

    def publish_world(self) -> None:
        """The world's shapes and where the robots' odometry frames start in it, for the viewer."""
        text = world_message(self.sim.world, self.sim.robots.values(), self.run)
        self.world_pub.publish(self.String(data=text))

    # -- bridges (ros_gz_bridge's stand-in: mlaunch.standins.gz_bridge)

    def on_bridges(self, msg: Any) -> None:
        """A bridge's list of topics: a cmd_vel bridged as TwistStamped is subscribed so."""
        try:
            bridges = json.loads(msg.data)["bridges"]
            announced = {str(b["gz_topic"]): str(b["ros_type"]) for b in bridges}
        except (ValueError, KeyError, TypeError) as exc:
            warn(f"ignoring a malformed bridge list on {BRIDGES_TOPIC}: {exc}")
            return
        self.bridged_types.update(announced)
        for topic in announced:
            held = self.commands.get(topic)
            if held is not None and held[2] != self.stamped(topic):
                self.node.destroy_subscription(held[1])
                self.subscribe_commands(held[0])

    def stamped(self, topic: str) -> bool:
        return self.bridged_types.get(topic) == "geometry_msgs/msg/TwistStamped"

    def subscribe_commands(self, robot: SimRobot) -> None:
        if robot.spec.drive is None or robot.drive is None:
            return
        topic = robot.spec.drive.cmd_topic
        stamped = self.stamped(topic)
        self.commands[topic] = (robot, subscribe_cmd_vel(self.node, robot, stamped), stamped)
        if stamped:
            say(
                f"model {robot.spec.name!r}: {topic} takes geometry_msgs/msg/TwistStamped (bridged)"
            )

    # -- spawning

    def on_spawn(self, msg: Any) -> None:
        """Handle one spawn request and answer it."""
        request_id: str | None = None
        name = ""
        try:
            request = parse_spawn_request(msg.data)
            request_id, name = request.id, request.name
            if request_id is not None and request_id in self.answered:
                # The same request again (a spawner's latched message seen twice): same answer.
                self.spawned_pub.publish(self.String(data=self.answered[request_id]))
                return
            name = self.spawn(request)
            reply: dict[str, object] = {"name": name, "ok": True, "error": ""}
        except (ValueError, ModelError) as exc:
            warn(f"spawn of {name or '?'!r} refused: {exc}")
            reply = {"name": name, "ok": False, "error": str(exc)}
        except Exception as exc:  # a bug must cost one model, not the whole simulation
            warn(f"spawn of {name or '?'!r} failed: {type(exc).__name__}: {exc}")
            reply = {"name": name, "ok": False, "error": f"internal error: {exc!r}"}
        if request_id is not None:
            reply["id"] = request_id
        text = json.dumps(reply)
        if request_id is not None:
            self.answered[request_id] = text
        self.spawned_pub.publish(self.String(data=text))

    def spawn(self, request: SpawnRequest) -> str:
        """Validate and add the model; return its (possibly renamed) name."""
        from mlaunch.standins.urdf import UrdfError, parse_urdf

        name = request.name
        if name in self.sim.robots:
            if not request.allow_renaming:
                raise ValueError(
                    f"an entity named {name!r} already exists; pick another -entity/-name"
                )
            name = free_name(name, self.sim.robots)
        try:
            robot = parse_urdf(request.urdf)
        except UrdfError as exc:
            raise ValueError(f"bad URDF for {name!r}: {exc}") from None
        spec = describe_model(robot, name, request.robot_namespace, self.sim.world.name)
        x, y, z, roll, pitch, yaw = request.pose
        sim_robot = self.sim.add_robot(spec, Pose2D(x, y, yaw))
        self.outputs.extend(make_outputs(self.node, self.sim, sim_robot, self.sensor_qos, self.tf))
        self.subscribe_commands(sim_robot)
        self.publish_world()
        say(f"spawned {spec.summary()} at x={x:g} y={y:g} z={z:g} yaw={yaw:g}")
        if roll or pitch:
            warn(
                f"model {name!r}: roll/pitch of the spawn pose are ignored (the stand-in is planar)"
            )
        for note in spec.warnings:
            warn(f"model {name!r}: {note}")
        if (
            spec.drive
            and (spec.drive.publish_odom_tf or spec.drive.publish_wheel_tf)
            and self.tf is None
        ):
            warn(f"model {name!r}: /tf is not published (tf2_msgs is not installed)")
        return name

    # -- publishing

    def publish_due(self) -> None:
        """Publish /clock and every robot output whose sim-time schedule has come up."""
        now = self.sim.now_ns
        sec, nanosec = divmod(now, 1_000_000_000)
        if self.clock_schedule.due(now):
            self.clock_msg.clock.sec = sec
            self.clock_msg.clock.nanosec = nanosec
            self.clock_pub.publish(self.clock_msg)
        for output in self.outputs:
            if output.schedule.due(now):
                output.publish(sec, nanosec)


if __name__ == "__main__":
    sys.exit(main())
