"""Simulator stand-in: a headless, deterministic 2D Gazebo for launch files that start one.

Run as ``python -m mlaunch.standins.sim ARGS...`` with the arguments ``gazebo``, ``gzserver``,
``gz sim`` or ``ign gazebo`` would have got. It loads the SDF world's static shapes, publishes
/clock, takes robots from the spawner stand-in (topic protocol below), drives them from their
diff-drive plugin's cmd_vel topic and publishes odometry, joint states, laser scans and IMU data
on the topics their ``<gazebo>`` plugin blocks name.

Spawn protocol (both topics reliable + transient_local, depth 10, std_msgs/String of JSON):
``/mlaunch_sim/spawn`` takes ``{"name", "x", "y", "z", "roll", "pitch", "yaw", "urdf"}`` plus
optional ``"id"``, ``"robot_namespace"`` and ``"allow_renaming"``; ``/mlaunch_sim/spawned``
answers ``{"name", "ok", "error"}`` (and the request's ``"id"``).

rclpy and the message packages are imported inside main() only.
"""

from __future__ import annotations

import argparse
import array
import json
import math
import os
import sys
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from mlaunch.standins.common import StopFlag, install_stop_flag
from mlaunch.standins.diffdrive import (
    DiffDrive,
    ImuParams,
    LidarParams,
    ModelError,
    ModelSpec,
    Pose2D,
    describe_model,
)
from mlaunch.standins.world import (
    RESOURCE_PATH_VARS,
    Disc,
    NoiseSampler,
    RayCaster,
    Shape,
    World,
    WorldError,
    clearance,
    load_world,
    seeded_rng,
)

PROG = "mlaunch sim"
SPAWN_TOPIC = "/mlaunch_sim/spawn"
SPAWNED_TOPIC = "/mlaunch_sim/spawned"
STEP_NS = 10_000_000  # fixed physics step: 10 ms of sim time
CLOCK_RATE = 100.0  # /clock messages per second of sim time
# Falling further behind real time than this (a suspended process, a slow machine) is not
# caught up in a burst: the simulation just runs slower than asked, as Gazebo does.
MAX_LAG_S = 0.25
EMPTY_WORLDS = ("empty.world", "empty.sdf")
# Gazebo system plugins whose ROS side the stand-in itself provides (/clock, spawning).
PROVIDED_PLUGINS = ("libgazebo_ros_init.so", "libgazebo_ros_factory.so")
STEPS_BETWEEN_SPINS = 10  # at most this many steps back to back before serving callbacks


class SimUsageError(Exception):
    """A command line the simulator cannot run with."""


def say(message: str) -> None:
    """One plain line on stdout (start-up and spawn notes)."""
    print(f"{PROG}: {message}", flush=True)


def warn(message: str) -> None:
    """One plain line on stderr."""
    print(f"{PROG}: warning: {message}", file=sys.stderr, flush=True)


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
    for flag in ("-s", "-g", "--levels", "--record", "--headless-rendering", "--wait-for-assets"):
        p.add_argument(flag, action="store_true", dest=f"ignored_{flag.lstrip('-')}")
    for flag in ("-z", "--iterations", "--network-role", "--network-secondaries", "--record-path",
                 "--playback", "--initial-sim-time", "--render-engine", "--render-engine-gui",
                 "--render-engine-server", "--physics-engine", "--gui-config"):  # fmt: skip
        p.add_argument(flag, dest=f"ignored_{flag.lstrip('-')}")
    p.add_argument("positional", nargs="*")
    return p


class _Parser(argparse.ArgumentParser):
    """argparse that raises instead of printing usage and exiting."""

    def error(self, message: str) -> Any:  # type: ignore[override]
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


# ---------------------------------------------------------------- simulation state (no ROS)


@dataclass
class Schedule:
    """Fires at a fixed rate of sim time (every step when the rate is 0, as in Gazebo)."""

    period_ns: int
    next_ns: int = 0

    @staticmethod
    def every(rate: float, start_ns: int) -> Schedule:
        """A schedule at ``rate`` Hz whose first firing is at ``start_ns``."""
        return Schedule(0 if rate <= 0 else max(1, round(1e9 / rate)), start_ns)

    def due(self, now_ns: int) -> bool:
        """True (and advance) when ``now_ns`` has reached the next firing."""
        if now_ns < self.next_ns:
            return False
        self.next_ns += self.period_ns
        if self.next_ns <= now_ns:  # skipped firings are dropped, keeping the phase
            missed = (now_ns - self.next_ns) // self.period_ns + 1 if self.period_ns else 0
            self.next_ns += missed * self.period_ns
        return True


@dataclass
class SimRobot:
    """One spawned model's moving state, noise streams and collision surroundings."""

    spec: ModelSpec
    spawn: Pose2D
    z: float
    drive: DiffDrive | None
    obstacles: list[Shape]
    lidar_noise: dict[str, NoiseSampler] = field(default_factory=dict)
    imu_noise: dict[str, list[NoiseSampler]] = field(default_factory=dict)
    forward_accel: float = 0.0

    @property
    def pose(self) -> Pose2D:
        """Where the root link is now."""
        return self.drive.pose if self.drive else self.spawn

    def disc(self) -> Disc:
        """The robot as an obstacle for the others' lidars and bumpers."""
        p = self.pose
        zmin, zmax = self.spec.height
        return Disc(self.spec.name, p.x, p.y, self.spec.radius, self.z + zmin, self.z + zmax)


class Simulation:
    """The world, the robots, and a fixed-step clock; knows nothing about ROS."""

    def __init__(self, world: World, seed: int, step_ns: int = STEP_NS):
        self.world = world
        self.seed = seed
        self.step_ns = step_ns
        self.now_ns = 0
        self.caster = RayCaster(world.shapes)
        self.robots: dict[str, SimRobot] = {}

    def add_robot(self, spec: ModelSpec, spawn: Pose2D) -> SimRobot:
        """Place a described model at its spawn pose, resting on the ground.

        Gazebo drops a model spawned at any height onto the ground plane; the stand-in puts it
        there at once, its lowest collision point at z = 0.
        """
        z = -spec.height[0]
        drive = None
        if spec.drive:
            drive = DiffDrive(
                separation=spec.drive.wheel_separation,
                wheel_radius=spec.drive.wheel_diameter / 2,
                max_wheel_acceleration=spec.drive.max_wheel_acceleration,
                pivot=spec.axle,
                pose=spawn,
            )
        zmin, zmax = spec.height
        # A small floor margin: kerbs and floor tiles lower than 2 cm do not stop the robot.
        near = [s for s in self.world.shapes if s.zmax > z + max(zmin, 0.02) and s.zmin < z + zmax]
        robot = SimRobot(spec, spawn, z, drive, near)
        for lidar in spec.lidars:
            robot.lidar_noise[lidar.name] = lidar.noise.sampler(
                seeded_rng(self.seed, spec.name, lidar.name)
            )
        for imu in spec.imus:
            rng = seeded_rng(self.seed, spec.name, imu.name)
            robot.imu_noise[imu.name] = [
                n.sampler(rng) for n in (*imu.angular_velocity, *imu.linear_acceleration)
            ]
        self.robots[spec.name] = robot
        return robot

    def step(self) -> None:
        """Advance one fixed step: every drive moves unless it would hit something."""
        dt = self.step_ns / 1e9
        for robot in self.robots.values():
            if robot.drive is None:
                continue
            before = robot.drive.linear
            robot.drive.step(dt, self._blocker(robot))
            robot.forward_accel = (robot.drive.linear - before) / dt
        self.now_ns += self.step_ns

    def _blocker(self, robot: SimRobot) -> Callable[[Pose2D], bool]:
        others = [r.disc() for r in self.robots.values() if r is not robot]
        shapes: list[Shape] = [*robot.obstacles, *others]
        zmin, zmax = robot.z + robot.spec.height[0], robot.z + robot.spec.height[1]
        radius = robot.spec.radius

        def blocked(candidate: Pose2D) -> bool:
            after = clearance(shapes, candidate.x, candidate.y, radius, zmin, zmax)
            if after >= 0:
                return False
            # Already touching (spawned inside something): moves that free the robot are allowed.
            now = robot.pose
            return after < clearance(shapes, now.x, now.y, radius, zmin, zmax)

        return blocked

    def scan(self, robot: SimRobot, lidar: LidarParams) -> list[float]:
        """One noisy scan: exact ray casts, then Gazebo's noise clamped to the range limits."""
        p = robot.pose
        m = lidar.mount
        c, s = math.cos(p.yaw), math.sin(p.yaw)
        x, y = p.x + c * m.x - s * m.y, p.y + s * m.x + c * m.y
        others = [r.disc() for r in self.robots.values() if r is not robot]
        ranges = self.caster.scan(
            x, y, robot.z + m.z, p.yaw + m.yaw, lidar.scan, others, m.upside_down
        )
        noise = robot.lidar_noise[lidar.name]
        if noise.noise.is_zero:
            return ranges
        lo, hi = lidar.scan.range_min, lidar.scan.range_max
        return [r if r == math.inf else min(hi, max(lo, noise.apply(r))) for r in ranges]

    def imu(self, robot: SimRobot, imu: ImuParams) -> tuple[float, list[float]]:
        """(yaw, [wx, wy, wz, ax, ay, az]) in the sensor frame, noise applied."""
        drive = robot.drive
        v = drive.linear if drive else 0.0
        w = drive.angular if drive else 0.0
        # Body-frame specific force: forward acceleration, centripetal v*w, and gravity's reaction.
        ax, ay = robot.forward_accel, v * w
        c, s = math.cos(-imu.mount.yaw), math.sin(-imu.mount.yaw)
        raw = [0.0, 0.0, w, c * ax - s * ay, s * ax + c * ay, -self.world.gravity[2]]
        values = [n.apply(value) for n, value in zip(robot.imu_noise[imu.name], raw, strict=True)]
        yaw = robot.pose.yaw + imu.mount.yaw
        if imu.initial_orientation_as_reference:
            yaw -= robot.spawn.yaw + imu.mount.yaw
        return yaw, values


# ---------------------------------------------------------------- spawn requests


@dataclass
class SpawnRequest:
    """A validated ``/mlaunch_sim/spawn`` message."""

    name: str
    urdf: str
    pose: tuple[float, float, float, float, float, float]
    id: str | None = None
    robot_namespace: str = ""
    allow_renaming: bool = False


def parse_spawn_request(text: str) -> SpawnRequest:
    """Decode and check a spawn request; ValueError says what is wrong."""
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise ValueError(f"spawn request is not JSON: {exc}") from None
    if not isinstance(data, dict):
        raise ValueError(f"spawn request must be a JSON object, got {type(data).__name__}")
    name = data.get("name")
    if not isinstance(name, str) or not name:
        raise ValueError(f"spawn request 'name' must be a non-empty string, got {name!r}")
    urdf = data.get("urdf")
    if not isinstance(urdf, str):
        raise ValueError(f"spawn request 'urdf' must be the URDF text, got {type(urdf).__name__}")
    pose = []
    for key in ("x", "y", "z", "roll", "pitch", "yaw"):
        value = data.get(key, 0.0)
        if (
            isinstance(value, bool)
            or not isinstance(value, int | float)
            or not math.isfinite(value)
        ):
            raise ValueError(f"spawn request {key!r} must be a finite number, got {value!r}")
        pose.append(float(value))
    request_id = data.get("id")
    namespace = data.get("robot_namespace") or ""
    if not isinstance(namespace, str):
        raise ValueError(f"spawn request 'robot_namespace' must be a string, got {namespace!r}")
    x, y, z, roll, pitch, yaw = pose
    return SpawnRequest(
        name=name,
        urdf=urdf,
        pose=(x, y, z, roll, pitch, yaw),
        id=None if request_id is None else str(request_id),
        robot_namespace=namespace,
        allow_renaming=bool(data.get("allow_renaming", False)),
    )


def free_name(name: str, taken: Mapping[str, object]) -> str:
    """``name`` or, when taken, ``name_1``, ``name_2``... (gz create -allow_renaming)."""
    if name not in taken:
        return name
    n = 1
    while f"{name}_{n}" in taken:
        n += 1
    return f"{name}_{n}"


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
        rclpy.try_shutdown()


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


def _publisher(node: Any, msg_type: Any, topic: str, qos: Any) -> Any:
    """A publisher without rclpy's default QoS-event handlers.

    Each default handler joins every wait set, and rclpy rebuilds the wait set on each spin:
    with a dozen topics that was most of the simulator's CPU time at 100 steps per second.
    """
    from rclpy.event_handler import PublisherEventCallbacks

    callbacks = PublisherEventCallbacks(use_default_callbacks=False)
    return node.create_publisher(msg_type, topic, qos, event_callbacks=callbacks)


def _subscription(node: Any, msg_type: Any, topic: str, callback: Any, qos: Any) -> Any:
    """A subscription without rclpy's default QoS-event handlers (see _publisher)."""
    from rclpy.event_handler import SubscriptionEventCallbacks

    callbacks = SubscriptionEventCallbacks(use_default_callbacks=False)
    return node.create_subscription(msg_type, topic, callback, qos, event_callbacks=callbacks)


class RosBridge:
    """Publishers, subscriptions and reused messages around one Simulation."""

    def __init__(self, node: Any, sim: Simulation, clock_rate: float):
        from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
        from rosgraph_msgs.msg import Clock
        from std_msgs.msg import String

        self.node = node
        self.sim = sim
        self.sensor_qos = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)
        latched = QoSProfile(
            depth=10,
            reliability=ReliabilityPolicy.RELIABLE,
            durability=DurabilityPolicy.TRANSIENT_LOCAL,
        )
        self.clock_msg = Clock()
        self.clock_pub = _publisher(node, Clock, "/clock", self.sensor_qos)
        self.clock_schedule = Schedule.every(clock_rate, 0)
        self.String = String
        self.spawned_pub = _publisher(node, String, SPAWNED_TOPIC, latched)
        _subscription(node, String, SPAWN_TOPIC, self.on_spawn, latched)
        self.outputs: list[Output] = []
        self.answered: dict[str, str] = {}  # request id -> reply
        self.tf = _tf_support()

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


@dataclass
class Output:
    """One periodic publication: when (sim-time schedule) and how (a closure over a message)."""

    schedule: Schedule
    publish: Callable[[int, int], None]


def _tf_support() -> Any:
    """tf2_msgs' TFMessage when installed (it is not in the PyPI ROS wheels), else None."""
    try:
        from tf2_msgs.msg import TFMessage
    except ImportError:
        return None
    return TFMessage


def make_outputs(node: Any, sim: Simulation, robot: SimRobot, qos: Any, tf: Any) -> list[Output]:
    """Publishers and closures for every topic a spawned robot serves."""
    spec = robot.spec
    outputs: list[Output] = []
    start = sim.now_ns
    if spec.drive and robot.drive:
        drive = robot.drive
        _subscribe_cmd_vel(node, spec, drive)
        if spec.drive.publish_odom:
            outputs.append(
                Output(
                    Schedule.every(spec.drive.update_rate, start), _odom_publisher(node, robot, qos)
                )
            )
        if tf is not None and spec.drive.publish_odom_tf:
            outputs.append(
                Output(
                    Schedule.every(spec.drive.update_rate, start), _tf_publisher(node, robot, tf)
                )
            )
    if spec.joint_states:
        outputs.append(
            Output(
                Schedule.every(spec.joint_states.update_rate, start),
                _joint_state_publisher(node, robot, qos),
            )
        )
    for lidar in spec.lidars:
        outputs.append(
            Output(
                Schedule.every(lidar.update_rate, start),
                _scan_publisher(node, sim, robot, lidar, qos),
            )
        )
    for imu in spec.imus:
        outputs.append(
            Output(
                Schedule.every(imu.update_rate, start), _imu_publisher(node, sim, robot, imu, qos)
            )
        )
    return outputs


def _subscribe_cmd_vel(node: Any, spec: ModelSpec, drive: DiffDrive) -> None:
    from geometry_msgs.msg import Twist

    warned = [False]

    def on_twist(msg: Any) -> None:
        linear, angular = msg.linear.x, msg.angular.z
        if not (math.isfinite(linear) and math.isfinite(angular)):
            if not warned[0]:
                warn(f"model {spec.name!r}: ignoring non-finite cmd_vel ({linear}, {angular})")
                warned[0] = True
            return
        drive.command(linear, angular)

    assert spec.drive is not None
    _subscription(node, Twist, spec.drive.cmd_topic, on_twist, 10)


def _quaternion(msg: Any, yaw: float) -> None:
    msg.x = 0.0
    msg.y = 0.0
    msg.z = math.sin(yaw / 2)
    msg.w = math.cos(yaw / 2)


def _odom_publisher(node: Any, robot: SimRobot, qos: Any) -> Callable[[int, int], None]:
    from nav_msgs.msg import Odometry

    params = robot.spec.drive
    drive = robot.drive
    assert params is not None and drive is not None
    msg = Odometry()
    msg.header.frame_id = params.odometry_frame
    msg.child_frame_id = params.robot_base_frame
    cx, cy, cyaw = params.covariance
    covariance = [0.0] * 36
    covariance[0], covariance[7], covariance[35] = cx, cy, cyaw
    covariance[14] = covariance[21] = covariance[28] = 1e12  # z, roll, pitch are not estimated
    msg.pose.covariance = covariance
    msg.twist.covariance = covariance
    msg.pose.pose.position.z = robot.z
    publisher = _publisher(node, Odometry, params.odom_topic, qos)
    spawn = robot.spawn

    def publish(sec: int, nanosec: int) -> None:
        pose = drive.pose
        if params.odometry_source == 0:  # encoder odometry starts at zero where it was spawned
            dx, dy = pose.x - spawn.x, pose.y - spawn.y
            c, s = math.cos(-spawn.yaw), math.sin(-spawn.yaw)
            pose = Pose2D(c * dx - s * dy, s * dx + c * dy, pose.yaw - spawn.yaw)
        msg.header.stamp.sec = sec
        msg.header.stamp.nanosec = nanosec
        msg.pose.pose.position.x = pose.x
        msg.pose.pose.position.y = pose.y
        _quaternion(msg.pose.pose.orientation, pose.yaw)
        msg.twist.twist.linear.x = drive.linear
        msg.twist.twist.angular.z = drive.angular
        publisher.publish(msg)

    return publish


def _tf_publisher(node: Any, robot: SimRobot, tf_type: Any) -> Callable[[int, int], None]:
    from geometry_msgs.msg import TransformStamped

    params = robot.spec.drive
    drive = robot.drive
    assert params is not None and drive is not None
    transform = TransformStamped()
    transform.header.frame_id = params.odometry_frame
    transform.child_frame_id = params.robot_base_frame
    transform.transform.translation.z = robot.z
    msg = tf_type()
    publisher = _publisher(node, tf_type, "/tf", 100)

    def publish(sec: int, nanosec: int) -> None:
        transform.header.stamp.sec = sec
        transform.header.stamp.nanosec = nanosec
        transform.transform.translation.x = drive.pose.x
        transform.transform.translation.y = drive.pose.y
        _quaternion(transform.transform.rotation, drive.pose.yaw)
        msg.transforms = [transform]
        publisher.publish(msg)

    return publish


def _joint_state_publisher(node: Any, robot: SimRobot, qos: Any) -> Callable[[int, int], None]:
    from sensor_msgs.msg import JointState

    spec = robot.spec
    assert spec.joint_states is not None
    names = list(spec.joint_states.joints) or [j.name for j in spec.robot.movable_joints()]
    left = set(spec.drive.left_joints) if spec.drive else set()
    right = set(spec.drive.right_joints) if spec.drive else set()
    msg = JointState()
    msg.name = names
    publisher = _publisher(node, JointState, spec.joint_states.topic, qos)
    drive = robot.drive

    def publish(sec: int, nanosec: int) -> None:
        positions = [0.0] * len(names)
        velocities = [0.0] * len(names)
        if drive is not None:
            radius = drive.wheel_radius
            for i, joint in enumerate(names):
                if joint in left:
                    positions[i], velocities[i] = drive.left_angle, drive.left_speed / radius
                elif joint in right:
                    positions[i], velocities[i] = drive.right_angle, drive.right_speed / radius
        msg.header.stamp.sec = sec
        msg.header.stamp.nanosec = nanosec
        msg.position = array.array("d", positions)
        msg.velocity = array.array("d", velocities)
        publisher.publish(msg)

    return publish


def _scan_publisher(
    node: Any, sim: Simulation, robot: SimRobot, lidar: LidarParams, qos: Any
) -> Callable[[int, int], None]:
    from sensor_msgs.msg import LaserScan

    msg = LaserScan()
    msg.header.frame_id = lidar.frame_id
    msg.angle_min = lidar.scan.angle_min
    msg.angle_max = lidar.scan.angle_max
    msg.angle_increment = lidar.scan.increment
    msg.time_increment = 0.0
    msg.scan_time = 0.0 if lidar.update_rate <= 0 else 1.0 / lidar.update_rate
    msg.range_min = lidar.scan.range_min
    msg.range_max = lidar.scan.range_max
    msg.intensities = array.array("f", [0.0] * lidar.scan.samples)
    publisher = _publisher(node, LaserScan, lidar.topic, qos)

    def publish(sec: int, nanosec: int) -> None:
        msg.header.stamp.sec = sec
        msg.header.stamp.nanosec = nanosec
        msg.ranges = array.array("f", sim.scan(robot, lidar))
        publisher.publish(msg)

    return publish


def _imu_publisher(
    node: Any, sim: Simulation, robot: SimRobot, imu: ImuParams, qos: Any
) -> Callable[[int, int], None]:
    from sensor_msgs.msg import Imu

    msg = Imu()
    msg.header.frame_id = imu.frame_id
    gyro = [0.0] * 9
    accel = [0.0] * 9
    for i in range(3):
        gyro[4 * i] = imu.angular_velocity[i].stddev ** 2
        accel[4 * i] = imu.linear_acceleration[i].stddev ** 2
    msg.angular_velocity_covariance = gyro
    msg.linear_acceleration_covariance = accel
    publisher = _publisher(node, Imu, imu.topic, qos)

    def publish(sec: int, nanosec: int) -> None:
        yaw, (wx, wy, wz, ax, ay, az) = sim.imu(robot, imu)
        msg.header.stamp.sec = sec
        msg.header.stamp.nanosec = nanosec
        _quaternion(msg.orientation, yaw)
        msg.angular_velocity.x, msg.angular_velocity.y, msg.angular_velocity.z = wx, wy, wz
        msg.linear_acceleration.x, msg.linear_acceleration.y, msg.linear_acceleration.z = ax, ay, az
        publisher.publish(msg)

    return publish


if __name__ == "__main__":
    sys.exit(main())
