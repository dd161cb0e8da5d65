"""The ROS 1 -> ROS 2 node mapping: known ROS 1 packages and programs as their ROS 2 counterparts.

``NODE_MAP`` is the table: (ROS 1 package, program) -> how the node is rewritten. Each mapping
may rename the package or program, rewrite arguments and parameters, replace the node by other
items, and add notes and warnings that say what changed (docs/ros1.md lists them).
"""

from __future__ import annotations

import copy
import re
from collections.abc import Callable

from mlaunch.ros1.elements import Element, ElementReader
from mlaunch.ros1.model import (
    Cond,
    Dropped,
    Group,
    Item,
    NodeItem,
    Params,
    ProcessItem,
    Value,
    describe_value,
    merge,
    static_text,
    text,
)
from mlaunch.ros1.scope import Consumer, Out
from mlaunch.ros1.server import DROPPED

_PERIOD = ", period_ms"
_EULER = ("x", "y", "z", "yaw", "pitch", "roll")
_QUATERNION = ("x", "y", "z", "qx", "qy", "qz", "qw")
_GZSERVER = ("gzserver", "-s", "libgazebo_ros_init.so", "-s", "libgazebo_ros_factory.so")


class NodeMapper(ElementReader):
    """Rewrites the nodes of known ROS 1 packages while a file is read (see ``NODE_MAP``)."""

    def map_node(self, node: NodeItem, el: Element, out: Out) -> list[Item]:
        """The items a ROS 1 node becomes: mapped by ``NODE_MAP``, else the node as it is."""
        mapping = NODE_MAP.get((static_text(node.package), static_text(node.executable)))
        return [node] if mapping is None else mapping(self, node, el, out)

    def map_rsp(self, node: NodeItem, el: Element, out: Out) -> list[Item]:
        """ROS 1 robot_state_publisher (also ``state_publisher``): the global description."""
        if static_text(node.executable) == "state_publisher":
            node.notes.append(
                "ROS 1 robot_state_publisher/state_publisher is robot_state_publisher in ROS 2"
            )
            node.executable = text("robot_state_publisher")
        kept: Params = []
        for name, value in node.parameters:
            if static_text(name) in DROPPED["robot_state_publisher"]:
                node.warnings.append(
                    f"parameter {static_text(name)} of ROS 1 robot_state_publisher does not exist"
                    " in ROS 2 (frames are never prefixed; static transforms always go to"
                    " /tf_static): dropped"
                )
                continue
            kept.append((name, value))
        node.parameters = kept
        if not any(static_text(n) == "robot_description" for n, _ in node.parameters):
            out.consumers.append(Consumer(node, "robot_description"))
        return [node]

    def map_tf_static(self, node: NodeItem, el: Element, out: Out) -> list[Item]:
        """ROS 1 tf's static_transform_publisher (with a period): tf2_ros's named options."""
        return self.map_static_tf(node, ros1_tf=True)

    def map_tf2_static(self, node: NodeItem, el: Element, out: Out) -> list[Item]:
        """ROS 1 tf2_ros's static_transform_publisher: tf2_ros's named options."""
        return self.map_static_tf(node, ros1_tf=False)

    def map_static_tf(self, node: NodeItem, ros1_tf: bool) -> list[Item]:
        args = node.arguments
        counts = (9, 10) if ros1_tf else (8, 9)
        node.package = text("tf2_ros")
        if len(args) not in counts:
            node.warnings.append(
                f"static_transform_publisher takes {counts[0]} or {counts[1]} arguments (x y z"
                f" yaw pitch roll | x y z qx qy qz qw, frame, child{_PERIOD if ros1_tf else ''}),"
                f" got {len(args)}: passed to tf2_ros unchanged"
            )
        else:
            node.arguments = self.static_tf_arguments(node, list(args), ros1_tf)
            node.shell_args = None
        program = "tf2_ros static_transform_publisher"
        if self.converting or self.available("tf2_ros", "static_transform_publisher"):
            return [node]
        frames = " -> ".join(describe_value(a) for a in _frame_args(node.arguments))
        return [
            Dropped(
                origin=node.origin,
                condition=node.condition,
                warnings=[
                    f"{program} is not installed and mlaunch's stand-in for it needs tf2_msgs"
                    f" (./scripts/setup builds it): the static transform {frames} is not"
                    " published (the node is dropped; it runs where either is installed)",
                    *node.warnings,
                ],
                node=node,
            )
        ]

    def static_tf_arguments(self, node: NodeItem, args: list[Value], ros1_tf: bool) -> list[Value]:
        if ros1_tf:
            period = describe_value(args.pop())
            node.warnings.append(
                f"the period ({period} ms) of ROS 1 tf static_transform_publisher is dropped:"
                " tf2_ros publishes a static transform once, latched on /tf_static"
            )
        numbers, frames = args[:-2], args[-2:]
        flags = _EULER if len(numbers) == 6 else _QUATERNION
        out: list[Value] = []
        for flag, value in zip(flags, numbers, strict=True):
            out += [text(f"--{flag}"), value]
        stripped = [_strip_slash(f) for f in frames]
        if stripped != frames:
            node.warnings.append("frame ids lose their leading '/' (tf2 rejects it)")
        out += [text("--frame-id"), stripped[0], text("--child-frame-id"), stripped[1]]
        node.notes.append(
            "ROS 1 static_transform_publisher arguments, written as tf2_ros's named options"
        )
        return out

    def available(self, package: str, executable: str) -> bool:
        """Whether a node of the package can start here: installed, or a stand-in exists."""
        from mlaunch import standins

        if self.index.installed(package) is not None:
            return True
        return standins.standin_for_package(package, executable) is not None

    def map_rviz(self, node: NodeItem, el: Element, out: Out) -> list[Item]:
        """ROS 1 rviz: rviz2, with a warning when its config is a ROS 1 one."""
        node.package = text("rviz2")
        node.executable = text("rviz2")
        node.notes.append("ROS 1 rviz/rviz is rviz2/rviz2 in ROS 2")
        config = _option_value(node.arguments, ("-d", "--display-config"))
        if config is None:
            return [node]
        path = self.resolve_static(config, el)
        reason = "could not be checked when the file was read" if path is None else ""
        if path is not None:
            reason = _rviz_config_format(path)
        if reason:
            node.warnings.append(
                f"the RViz config {describe_value(config)} {reason}: rviz2 cannot load ROS 1"
                " configs (display classes rviz/... are rviz_default_plugins/... in rviz2);"
                " save a new one from rviz2"
            )
        return [node]

    def map_jsp(self, node: NodeItem, el: Element, out: Out) -> list[Item]:
        """joint_state_publisher: ``use_gui`` picks joint_state_publisher_gui in ROS 2."""
        kept: Params = []
        for name, value in node.parameters:
            if static_text(name) == "use_gui":
                node.gui = value
            else:
                kept.append((name, value))
        node.parameters = kept
        if node.gui is None:
            out.consumers.append(Consumer(node, "use_gui"))
        self.jsp_nodes.append(node)
        return [node]

    def map_arbotix(self, node: NodeItem, el: Element, out: Out) -> list[Item]:
        """The ArbotiX driver: a simulator and a spawner (named when the file is read)."""
        sim = ProcessItem(
            origin=node.origin,
            condition=node.condition,
            cmd=[text(a) for a in _GZSERVER],
            output=node.output or text("screen"),
            respawn=node.respawn,
            respawn_delay=node.respawn_delay,
            required=node.required,
            prefix=node.prefix,
            env=node.env,
            machine=node.machine,
        )
        spawn = NodeItem(
            origin=node.origin,
            condition=node.condition,
            package=text("gazebo_ros"),
            executable=text("spawn_entity.py"),
            name=None,
            namespace=node.namespace,
            output=text("screen"),
        )
        names = list(dict.fromkeys(describe_value(n).split(".")[0] for n, _ in node.parameters))
        sim_param = next((v for n, v in node.parameters if static_text(n) == "sim"), None)
        board = ""
        if sim_param is not None and sim_param.literal is False:
            board = " (sim is false: the real ArbotiX board is not driven)"
        used = f"; its parameters ({', '.join(names)}) are not used{board}" if names else board
        self.arbotix.append((node, sim, spawn, used))
        return [sim, spawn]

    def finish_arbotix(self) -> None:
        """The spawned entity is named after the robot model (known once the file is read)."""
        model = next((d.model for d in self.descriptions if d.model), None)
        for node, sim, spawn, used in self.arbotix:
            entity = model or static_text(node.name) or "robot"
            spawn.arguments = [text(a) for a in ("-topic", "robot_description", "-entity", entity)]
            sim.warnings.append(
                "arbotix_python arbotix_driver (the ArbotiX diff-drive controller) has no ROS 2"
                " package: it is replaced by a Gazebo simulator (gzserver; mlaunch's stand-in"
                " where Gazebo is not installed) that drives the robot from /cmd_vel through the"
                " diff-drive plugin of its URDF, and spawn_entity.py spawns robot_description"
                f" as {entity!r}{used}"
            )
            sim.notes.append(f"ROS 1 node {describe_value(node.name or ())!s} (arbotix_driver)")

    def finish_jsp(self) -> None:
        for node in self.jsp_nodes:
            if node.gui is None:
                continue
            if node.gui.literal is False:
                continue
            if node.gui.literal is True:
                node.executable = node.package = text("joint_state_publisher_gui")
            node.warnings.append(
                "use_gui: ROS 2's joint_state_publisher has no GUI; joint_state_publisher_gui"
                " (its own package) runs when use_gui is true"
            )


def _strip_slash(value: Value) -> Value:
    if value and isinstance(value[0], str) and value[0].startswith("/"):
        return merge([value[0].lstrip("/"), *value[1:]])
    return value


def _frame_args(arguments: list[Value]) -> list[Value]:
    found = []
    for i, item in enumerate(arguments[:-1]):
        if static_text(item) in ("--frame-id", "--child-frame-id"):
            found.append(arguments[i + 1])
    return found or arguments[-3:-1]


def _option_value(arguments: list[Value], flags: tuple[str, ...]) -> Value | None:
    for i, item in enumerate(arguments[:-1]):
        if static_text(item) in flags:
            return arguments[i + 1]
    return None


def _rviz_config_format(path: str) -> str:
    """Why a config is not for rviz2 ('' when it looks like one)."""
    try:
        with open(path, encoding="utf-8", errors="replace") as f:
            head = f.read(65536)
    except OSError as e:
        return f"cannot be read ({e.strerror})"
    if re.search(r"Class:\s*rviz/", head):
        return "is a ROS 1 RViz config (Class: rviz/...)"
    return ""


def lower_gui(items: list[Item]) -> None:
    """joint_state_publisher with a use_gui known only when resolving: both, under conditions."""
    for i, item in enumerate(items):
        if isinstance(item, Group):
            lower_gui(item.items)
        elif isinstance(item, NodeItem) and item.gui is not None and item.gui.dynamic:
            items[i] = _gui_switch(item, item.gui.dynamic)


def _gui_switch(node: NodeItem, gui: Value) -> Group:
    plain = copy.copy(node)
    plain.gui, plain.warnings, plain.condition = None, [], Cond(gui, unless=True)
    with_gui = copy.copy(plain)
    plain.notes = [*node.notes, "without the GUI (use_gui false)"]
    with_gui.notes = [*node.notes, "use_gui true: the GUI is its own package in ROS 2"]
    with_gui.package = with_gui.executable = text("joint_state_publisher_gui")
    with_gui.condition = Cond(gui)
    items: list[Item] = [plain, with_gui]
    return Group(origin=node.origin, condition=node.condition, warnings=node.warnings, items=items)


# (ROS 1 package, program) -> how the node is rewritten for ROS 2.
Mapping = Callable[[NodeMapper, NodeItem, Element, Out], list[Item]]
NODE_MAP: dict[tuple[str | None, str | None], Mapping] = {
    ("robot_state_publisher", "robot_state_publisher"): NodeMapper.map_rsp,
    ("robot_state_publisher", "state_publisher"): NodeMapper.map_rsp,
    ("tf", "static_transform_publisher"): NodeMapper.map_tf_static,
    ("tf2_ros", "static_transform_publisher"): NodeMapper.map_tf2_static,
    ("rviz", "rviz"): NodeMapper.map_rviz,
    ("joint_state_publisher", "joint_state_publisher"): NodeMapper.map_jsp,
    ("arbotix_python", "arbotix_driver"): NodeMapper.map_arbotix,
}
