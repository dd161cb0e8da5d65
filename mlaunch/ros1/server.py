"""ROS 1's parameter server mapped onto ROS 2 nodes by ROS 1's name rules.

When mlaunch runs a roslaunch file on ROS 2, the file is also resolved as roslaunch resolves it
(``mlaunch.ros1.config``, with the run's arguments): one parameter server for the whole tree of
included files, whatever the order of the tags. Each ROS 2 node then gets, as its own
parameters, what it would read in ROS 1 (docs/ros1.md, *Parameters*):

- ``/use_sim_time``: every node;
- a name under the node's own name (``/gazebo/x`` for node ``/gazebo``): private, ``x``;
- ``robot_description`` (robot_state_publisher only): ``searchParam``, the nearest one up from
  the node's namespace;
- any other name, relative to the deepest of the node's namespaces (its own, or one above it)
  that holds it (``a/b`` -> ``a.b``), unless its first part there is another node's name or a
  namespace that holds nodes (it belongs to those); a global of an enclosing namespace reaches
  the nodes of the namespaces inside it, as a SetParameter of its scope would;
- its own parameters (under its name) go in its params file, as the mapping writes them, less
  those its ROS 2 counterpart does not take (``DROPPED``).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from mlaunch.ros1.config import Config, global_ns

SERVER_KEY = "mlaunch_ros1_parameter_server"
# Global names the mapping gives only to the nodes that read them (or that pick a program).
SPECIAL = ("robot_description", "use_gui")
# Private parameters of ROS 1 programs their ROS 2 counterparts do not take (docs/ros1.md).
DROPPED = {
    "robot_state_publisher": ("tf_prefix", "use_tf_static"),
    "joint_state_publisher": ("use_gui",),
}


@dataclass
class Server:
    """The parameter server of one roslaunch tree, and the names of its nodes."""

    config: Config
    node_names: set[str] = field(default_factory=set)
    namespaces: set[str] = field(default_factory=set)  # every namespace that holds a node

    @classmethod
    def of(cls, config: Config) -> Server:
        server = cls(config)
        for node in config.nodes:
            server.node_names.add(node.full_name)
            ns = node.namespace
            while ns != "/":
                server.namespaces.add(ns)
                ns = global_ns(ns.rstrip("/").rsplit("/", 1)[0] or "/")
        return server

    def parameters_of(
        self, name: str | None, namespace: str, package: str
    ) -> tuple[dict[str, Any], dict[str, Any]]:
        """A node's ROS 1 parameters as ROS 2 names (``a.b``) and values: (its own, under its
        name, with robot_state_publisher's robot_description; the others it would read)."""
        ns = global_ns(namespace or "/")
        full = ns + name + "/" if name else None
        ranked: list[tuple[int, str, Any]] = []
        for key, value in self.config.params.items():
            local = self.local_name(key, ns, full)
            if local is not None:
                ranked.append((local[0], local[1].replace("/", "."), value))
        # outer namespaces first, then inner ones: where SetParameters of nested scopes would
        # put them (a later one wins)
        ranked.sort(key=lambda r: r[0])
        dropped = DROPPED.get(package, ())
        own = {n: v for rank, n, v in ranked if rank < 0 and n not in dropped}
        shared = {n: v for rank, n, v in ranked if rank >= 0}
        if package == "robot_state_publisher":
            description = self.search(ns, "robot_description")
            if description is not None:
                own = {"robot_description": description, **own}
        return own, shared

    def local_name(self, key: str, ns: str, full: str | None) -> tuple[int, str] | None:
        """(rank, name) of a parameter for a node: its depth of scope, and its local name."""
        if key == "/use_sim_time":
            return 0, "use_sim_time"
        if full is not None and key.startswith(full):
            return -1, key[len(full) :]
        scope = self.nearest(key, ns)
        if scope is None:
            return None
        rest = key[len(scope) :]
        first = rest.split("/", 1)[0]
        if "/" not in rest and first in SPECIAL:
            return None
        if scope + first in self.node_names or scope + first + "/" in self.namespaces:
            return None  # another node's private parameter, or a namespace's with nodes
        return len(scope), rest

    @staticmethod
    def nearest(key: str, ns: str) -> str | None:
        """The deepest of the node's namespaces (its own, then each one up) holding ``key``."""
        while not key.startswith(ns):
            if ns == "/":
                return None
            ns = global_ns(ns.rstrip("/").rsplit("/", 1)[0] or "/")
        return ns

    def search(self, ns: str, name: str) -> Any:
        """rospy's searchParam: the nearest ``name`` from ``ns`` up to the root."""
        while True:
            key = ns + name
            if key in self.config.params:
                return self.config.params[key]
            if ns == "/":
                return None
            ns = global_ns(ns.rstrip("/").rsplit("/", 1)[0] or "/")


def flat(found: Mapping[str, Any]) -> dict[str, Any]:
    """``<param type="yaml">`` maps as dotted ROS 2 names."""
    out: dict[str, Any] = {}
    for name, value in found.items():
        if isinstance(value, dict):
            for key, inner in flat({str(k): v for k, v in value.items()}).items():
                out[f"{name}.{key}"] = inner
        else:
            out[name] = value
    return out
