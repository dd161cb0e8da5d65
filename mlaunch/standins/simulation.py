"""The simulator's state without ROS: robots on a world, stepped in fixed sim-time increments.

``Simulation`` holds the world's shapes and the spawned robots, moves their drives without
letting them pass through anything, and answers sensor questions (laser ranges, IMU readings).
``Schedule`` says when a periodic output is due in sim time. Nothing here imports rclpy.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

from mlaunch.standins.diffdrive import DiffDrive, ModelSpec, Pose2D
from mlaunch.standins.sensors import ImuParams, LidarParams, Mount
from mlaunch.standins.world import (
    Disc,
    NoiseSampler,
    RayCaster,
    Shape,
    World,
    clearance,
    seeded_rng,
)

STEP_NS = 10_000_000  # fixed physics step: 10 ms of sim time


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
        x, y, z, yaw = self.sensor_pose(robot, lidar.mount)
        ranges = self.caster.scan(
            x, y, z, yaw, lidar.scan, self.others(robot), lidar.mount.upside_down
        )
        noise = robot.lidar_noise[lidar.name]
        if noise.noise.is_zero:
            return ranges
        lo, hi = lidar.scan.range_min, lidar.scan.range_max
        return [r if r == math.inf else min(hi, max(lo, noise.apply(r))) for r in ranges]

    def sensor_pose(self, robot: SimRobot, mount: Mount) -> tuple[float, float, float, float]:
        """(x, y, z, yaw) in the world of a sensor mounted on a robot."""
        p = robot.pose
        c, s = math.cos(p.yaw), math.sin(p.yaw)
        x, y = p.x + c * mount.x - s * mount.y, p.y + s * mount.x + c * mount.y
        return x, y, robot.z + mount.z, p.yaw + mount.yaw

    def others(self, robot: SimRobot) -> list[Disc]:
        """The other robots, as discs a sensor of ``robot`` can see."""
        return [r.disc() for r in self.robots.values() if r is not robot]

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
