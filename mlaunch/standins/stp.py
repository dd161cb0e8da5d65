"""Stand-in for tf2_ros static_transform_publisher: ``python -m mlaunch.standins.stp ARGS``.

It accepts the real program's command line, the flag form (``--x --y --z``, ``--qx --qy --qz
--qw`` or ``--roll --pitch --yaw``, ``--frame-id``, ``--child-frame-id``) and the old positional
form (``x y z yaw pitch roll frame child`` or ``x y z qx qy qz qw frame child``, with the real
program's deprecation warning), and latches the one transform on /tf_static under the real node
name (``static_transform_publisher_`` and 16 random characters, unless remapped). Bad arguments
are one error line, the usage and exit status 1, as the real program prints them.
"""

from __future__ import annotations

import random
import string
import sys
from collections.abc import Sequence
from typing import TYPE_CHECKING

from mlaunch.plan.errors import StandinError
from mlaunch.standins import transforms
from mlaunch.standins.common import EXIT_FAILURE, EXIT_OK, init_ros, spin_until_shutdown

if TYPE_CHECKING:
    from rclpy.node import Node

USAGE = """\
usage: static_transform_publisher [--x X] [--y Y] [--z Z] [--qx QX] [--qy QY] [--qz QZ] \
[--qw QW] [--roll ROLL] [--pitch PITCH] [--yaw YAW] --frame-id FRAME_ID --child-frame-id \
CHILD_FRAME_ID

Publishes one static transform on /tf_static (mlaunch's stand-in for tf2_ros's program).
With no translation or rotation it is the identity. Translations are in metres; the rotation is
roll, pitch, yaw in radians or a quaternion. The old form X Y Z YAW PITCH ROLL FRAME CHILD (or
X Y Z QX QY QZ QW FRAME CHILD) is accepted, deprecated."""

TRANSLATION = ("--x", "--y", "--z")
QUATERNION = ("--qx", "--qy", "--qz", "--qw")
EULER = ("--roll", "--pitch", "--yaw")
FRAMES = ("--frame-id", "--child-frame-id")


class UsageError(StandinError, ValueError):
    """The command line cannot be understood; the message says which argument and why."""


class StaticTransform:
    """One parsed command line: where the child frame is in the parent frame."""

    def __init__(self) -> None:
        self.xyz = [0.0, 0.0, 0.0]
        self.rotation = [0.0, 0.0, 0.0, 1.0]
        self.frame_id = ""
        self.child_frame_id = ""
        self.help = False
        self.deprecated_form = False


def _number(option: str, text: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise UsageError(f"Failed to parse {option} argument as float (got {text!r})")


def parse_args(args: Sequence[str]) -> StaticTransform:
    """The transform a command line (ROS arguments removed, program name excluded) asks for."""
    result = StaticTransform()
    flags: dict[str, str] = {}
    positional: list[str] = []
    known = {*TRANSLATION, *QUATERNION, *EULER, *FRAMES}
    items = list(args)
    while items:
        item = items.pop(0)
        if item in ("-h", "--help"):
            result.help = True
        elif item in known:
            if not items:
                raise UsageError(f"Not enough arguments for {item}")
            flags[item] = items.pop(0)
        else:
            positional.append(item)
    if result.help:
        return result
    numbers = {k: _number(k, v) for k, v in flags.items() if k not in FRAMES}
    if any(k in numbers for k in EULER) and any(k in numbers for k in QUATERNION):
        raise UsageError("Cannot specify both quaternion and Euler rotations")
    for index, key in enumerate(TRANSLATION):
        result.xyz[index] = numbers.get(key, 0.0)
    for index, key in enumerate(QUATERNION):
        result.rotation[index] = numbers.get(key, result.rotation[index])
    if any(k in numbers for k in EULER):
        roll, pitch, yaw = (numbers.get(k, 0.0) for k in EULER)
        result.rotation = list(transforms.quaternion_from_rpy(roll, pitch, yaw))
    result.frame_id = flags.get("--frame-id", "")
    result.child_frame_id = flags.get("--child-frame-id", "")
    if len(positional) in (8, 9):
        if any(k in flags for k in (*TRANSLATION, *QUATERNION, *FRAMES)):
            raise UsageError("Cannot specify both new-style (flags) and old-style (arguments)")
        _positional(result, positional)
    elif positional:
        raise UsageError(f"Extra unparsed arguments on command-line: {' '.join(positional)}")
    if not result.frame_id:
        raise UsageError("Frame id must not be empty (give --frame-id FRAME_ID)")
    if not result.child_frame_id:
        raise UsageError("Child frame id must not be empty (give --child-frame-id CHILD_FRAME_ID)")
    return result


def _positional(result: StaticTransform, values: list[str]) -> None:
    """The old form: x y z yaw pitch roll frame child, or x y z qx qy qz qw frame child."""
    result.deprecated_form = True
    result.xyz = [_number(name, text) for name, text in zip("xyz", values[:3], strict=True)]
    if len(values) == 8:
        yaw, pitch, roll = (
            _number(n, t) for n, t in zip(("yaw", "pitch", "roll"), values[3:6], strict=True)
        )
        result.rotation = list(transforms.quaternion_from_rpy(roll, pitch, yaw))
    else:
        names = ("qx", "qy", "qz", "qw")
        result.rotation = [_number(n, t) for n, t in zip(names, values[3:7], strict=True)]
    result.frame_id, result.child_frame_id = values[-2], values[-1]


def unique_node_name() -> str:
    """The real program's node name: a fixed prefix and 16 random letters and digits."""
    alphabet = string.digits + string.ascii_letters
    return "static_transform_publisher_" + "".join(random.choices(alphabet, k=16))


def main(argv: Sequence[str] | None = None) -> int:
    """Publish the transform until shutdown; 1 with the error and the usage on bad arguments."""
    from rclpy.node import Node
    from rclpy.parameter import Parameter
    from rclpy.utilities import remove_ros_args

    args = [sys.argv[0], *(sys.argv[1:] if argv is None else argv)]
    try:
        wanted = parse_args(remove_ros_args(args)[1:])
    except UsageError as exc:
        print(f"[ERROR] [static_transform_publisher]: error parsing command line arguments: {exc}")
        print(USAGE)
        return EXIT_FAILURE
    if wanted.help:
        print(USAGE)
        return EXIT_OK
    if not transforms.have_tf2_msgs():
        print(f"[ERROR] [static_transform_publisher]: {transforms.MISSING_NOTE}", file=sys.stderr)
        return EXIT_FAILURE
    if wanted.deprecated_form:
        print(
            "[WARN] [static_transform_publisher]: Old-style arguments are deprecated; "
            "see --help for new-style arguments",
            file=sys.stderr,
        )
    stop = init_ros(args, "static_transform_publisher")
    if stop is None:
        return EXIT_FAILURE
    values: dict[str, float | str] = {
        "translation.x": wanted.xyz[0],
        "translation.y": wanted.xyz[1],
        "translation.z": wanted.xyz[2],
        "rotation.x": wanted.rotation[0],
        "rotation.y": wanted.rotation[1],
        "rotation.z": wanted.rotation[2],
        "rotation.w": wanted.rotation[3],
        "frame_id": wanted.frame_id,
        "child_frame_id": wanted.child_frame_id,
    }
    # Explicit overrides win over --ros-args -p, as the real program's NodeOptions overrides do.
    overrides = [Parameter(name, value=value) for name, value in values.items()]
    node = Node(unique_node_name(), parameter_overrides=overrides)
    return spin_until_shutdown(node, lambda: _start(node, values), {UsageError: ""}, stop)


def _start(node: Node, values: dict[str, float | str]) -> None:
    """Declare the read-only parameters the real node has, then latch their transform."""
    from rcl_interfaces.msg import ParameterDescriptor

    read_only = ParameterDescriptor(read_only=True)
    declared = {
        name: node.declare_parameter(name, value, read_only).value for name, value in values.items()
    }
    parent, child = declared["frame_id"], declared["child_frame_id"]
    if parent == child:
        raise UsageError(f"cannot publish static transform from {parent!r} to {child!r}, exiting")
    xyz = tuple(float(declared[f"translation.{a}"]) for a in "xyz")
    rotation = tuple(float(declared[f"rotation.{a}"]) for a in "xyzw")
    stamp = node.get_clock().now().to_msg()
    # The node keeps the publisher alive after the broadcaster object goes.
    broadcaster = transforms.StaticBroadcaster(node)
    broadcaster.send([transforms.transform(parent, child, xyz, rotation, stamp)])  # type: ignore[arg-type]
    node.get_logger().info(
        "Spinning until stopped - publishing transform\n"
        f"translation: ('{xyz[0]:f}', '{xyz[1]:f}', '{xyz[2]:f}')\n"
        f"rotation: ('{rotation[0]:f}', '{rotation[1]:f}', '{rotation[2]:f}', '{rotation[3]:f}')\n"
        f"from '{parent}' to '{child}'"
    )


if __name__ == "__main__":
    sys.exit(main())
