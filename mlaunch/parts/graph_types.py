"""What the ROS bridge raises and hands out, and its pure helpers (names, domain ids, types).

Kept apart from mlaunch.parts.bridge's RosGraph so the graph module stays about the graph; nothing
here imports rclpy at module level either (``message_class`` and ``import_ros`` do, when called).
"""

from __future__ import annotations

import importlib
import re
import threading
import time
from collections import deque
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from mlaunch.plan.errors import MlaunchError

INSTALL_HINT = "pip install 'mlaunch[ros]'"
MAX_DOMAIN_ID = 232  # highest id whose Fast DDS / Cyclone DDS port numbers stay valid
TRANSITION_IDS = {  # lifecycle_msgs/msg/Transition ids; 'shutdown' depends on the state
    "configure": 1,
    "cleanup": 2,
    "activate": 3,
    "deactivate": 4,
    "shutdown": 0,
}
# rcl_lifecycle leaves TransitionEvent.transition empty; the intermediate state names it.
TRANSITION_OF_STATE = {
    "configuring": "configure",
    "cleaningup": "cleanup",
    "activating": "activate",
    "deactivating": "deactivate",
    "shuttingdown": "shutdown",
    "errorprocessing": "error",
}
_MESSAGE_TYPE = re.compile(r"^([A-Za-z][A-Za-z0-9_]*)/(?:msg/)?([A-Z][A-Za-z0-9]*)$")
NODE_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")


class RosBridgeError(MlaunchError, RuntimeError):
    """Something between mlaunch and the ROS graph went wrong."""


class RosUnavailable(RosBridgeError):
    """rclpy (or a message package it needs) is not installed in this Python."""


class RosInputError(RosBridgeError, ValueError):
    """A name, type, transition or domain id handed to the bridge is not valid."""


class RosTimeout(RosBridgeError, TimeoutError):
    """A ROS service did not appear or answer before its deadline."""


class GraphNotRunning(RosBridgeError):
    """The RosGraph was used before start() or after close()."""


@dataclass(frozen=True)
class TransitionResult:
    """What came of asking a managed node for a transition; `detail` explains a failure."""

    ok: bool
    node: str
    transition: str
    detail: str
    state: str | None = None  # the node's state read back afterwards, when it answered


@dataclass(frozen=True)
class TransitionEvent:
    """One step of a managed node's state machine, from its `transition_event` topic.

    A transition shows as two steps, e.g. unconfigured -> configuring, configuring -> inactive;
    `transition` ('configure') is the message's label or, as rcl_lifecycle leaves that empty,
    the one implied by the intermediate state (TRANSITION_OF_STATE).
    """

    node: str
    transition: str
    start_state: str
    goal_state: str
    transition_id: int
    received_at: float  # time.monotonic() when it arrived


class TopicWatch:
    """Counts and times the messages of one topic; filled by the RosGraph's executor thread.

    The subscription is made once the topic has a publisher, so the type (when not given) and
    the QoS can be taken from the publishers. `error` says why nothing can arrive (for example a
    message package that is not installed).
    """

    def __init__(self, topic: str, type_name: str | None, *, history: int = 4096) -> None:
        self.topic = topic
        self.type_name = type_name
        self.count = 0
        self.first_at: float | None = None
        self.last_at: float | None = None
        self.error: str | None = None
        self.subscribed = False
        self._stamps: deque[float] = deque(maxlen=history)
        self._last: Any = None
        self._closed = False
        self._cond = threading.Condition()
        self._listeners: list[Callable[[], None]] = []

    def __repr__(self) -> str:
        return f"TopicWatch({self.topic!r}, {self.type_name!r}, count={self.count})"

    def rate(self, window: float = 2.0) -> float:
        """Messages per second over the arrivals of the last `window` seconds (0.0 under two)."""
        if window <= 0:
            raise RosInputError(f"rate window must be > 0 seconds, got {window!r}")
        since = time.monotonic() - window
        with self._cond:
            recent = [t for t in self._stamps if t >= since]
        if len(recent) < 2 or recent[-1] <= recent[0]:
            return 0.0
        return (len(recent) - 1) / (recent[-1] - recent[0])

    def recent(self, window: float = 2.0) -> tuple[int, float]:
        """(messages, seconds from the first to the last of them) of the last `window` seconds:
        what a rate from `rate(window)` rests on."""
        since = time.monotonic() - window
        with self._cond:
            recent = [t for t in self._stamps if t >= since]
        return len(recent), (recent[-1] - recent[0]) if recent else 0.0

    def wait_count(self, n: int, timeout: float) -> bool:
        """Wait until at least `n` messages arrived; False at the deadline or on close."""
        with self._cond:
            self._cond.wait_for(lambda: self.count >= n or self._closed, timeout)
            return self.count >= n

    def listen(self, callback: Callable[[], None]) -> None:
        """Call ``callback`` (on the graph's thread) after each message; it must be quick."""
        self._listeners.append(callback)

    def last_message(self) -> Any:
        """The newest message received, or None."""
        with self._cond:
            return self._last

    def _on_message(self, message: Any) -> None:
        now = time.monotonic()
        with self._cond:
            self.count += 1
            self.first_at = now if self.first_at is None else self.first_at
            self.last_at = now
            self._stamps.append(now)
            self._last = message
            self._cond.notify_all()
        for listener in self._listeners:
            listener()

    def _close(self) -> None:
        with self._cond:
            self._closed = True
            self._cond.notify_all()


@dataclass
class PendingCall:
    """A service request in flight: the caller waits on `done`, close() sets it too."""

    future: Any
    done: threading.Event


def domain_id_from(environ: Mapping[str, str]) -> int:
    """ROS_DOMAIN_ID of `environ` as rcl reads it: unset or empty means domain 0."""
    raw = environ.get("ROS_DOMAIN_ID", "").strip()
    if not raw:
        return 0
    if not raw.isdigit() or int(raw) > MAX_DOMAIN_ID:
        raise RosInputError(
            f"ROS_DOMAIN_ID={raw!r} is not a domain id: use an integer from 0 to {MAX_DOMAIN_ID}",
            what="ROS_DOMAIN_ID",
        )
    return int(raw)


def node_fqn(node: str) -> str:
    """'/ns/name' for a node given as 'name', 'ns/name' or '/ns/name' (relative means absolute)."""
    fqn = node if node.startswith("/") else f"/{node}"
    parts = fqn[1:].split("/")
    if not all(NODE_NAME.match(part) for part in parts):
        raise RosInputError(
            f"node name {node!r} is not a fully qualified ROS node name like '/robot1/camera' "
            "(each part: letters, digits and '_', not starting with a digit)"
        )
    return fqn


def topic_name(topic: str) -> str:
    from rclpy.exceptions import InvalidTopicNameException
    from rclpy.validate_full_topic_name import validate_full_topic_name

    name = topic if topic.startswith("/") else f"/{topic}"
    try:
        validate_full_topic_name(name)
    except InvalidTopicNameException as exc:
        raise RosInputError(f"topic name {topic!r} is not valid: {exc}") from None
    return name


def message_class(type_name: str) -> Any:
    """The Python class of message type 'pkg/msg/Type' (or 'pkg/Type'), imported on demand."""
    match = _MESSAGE_TYPE.match(type_name)
    if match is None:
        raise RosInputError(
            f"message type {type_name!r} is not of the form 'package/msg/Type', "
            "e.g. 'sensor_msgs/msg/LaserScan'"
        )
    package, name = match.groups()
    module = import_ros(
        f"{package}.msg",
        f"message type {type_name!r} needs the ROS package {package!r}",
        f"install its Python messages (e.g. the ros-<distro>-{package.replace('_', '-')} wheel)",
    )
    cls = getattr(module, name, None)
    if cls is None:
        raise RosInputError(
            f"message type {type_name!r}: package {package!r} has no message {name}"
        )
    return cls


def import_ros(
    module: str, why: str = "the ROS bridge needs rclpy", hint: str = INSTALL_HINT
) -> Any:
    try:
        return importlib.import_module(module)
    except ImportError as exc:
        raise RosUnavailable(f"{why}, and importing {module} failed ({exc}): {hint}")


def qos_for(publishers: list[Any]) -> Any:
    """A QoS that matches every current publisher, and gets a latched topic's last message.

    Best effort matches reliable and best-effort publishers alike. Transient local matches only
    transient-local publishers, so it is used only when all of them are (a latched topic); then
    reliable too, when they all are, because that is what delivers the history to a late joiner.
    """
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

    offered = [info.qos_profile for info in publishers]
    latched = all(q.durability == DurabilityPolicy.TRANSIENT_LOCAL for q in offered)
    reliable = latched and all(q.reliability == ReliabilityPolicy.RELIABLE for q in offered)
    return QoSProfile(
        depth=10,
        reliability=ReliabilityPolicy.RELIABLE if reliable else ReliabilityPolicy.BEST_EFFORT,
        durability=DurabilityPolicy.TRANSIENT_LOCAL if latched else DurabilityPolicy.VOLATILE,
    )


def transition_label(transition: str) -> str:
    if transition not in TRANSITION_IDS:
        raise RosInputError(
            f"lifecycle transition {transition!r} is not one of {', '.join(TRANSITION_IDS)}"
        )
    return transition


def implied_transition(msg: Any) -> str:
    for state in (msg.goal_state.label, msg.start_state.label):
        if state in TRANSITION_OF_STATE:
            return TRANSITION_OF_STATE[state]
    return ""


def same_type(watch: TopicWatch, type_name: str | None) -> TopicWatch:
    if type_name is not None and watch.type_name not in (None, type_name):
        raise RosInputError(
            f"topic {watch.topic} is already watched as {watch.type_name}, not {type_name}"
        )
    return watch


def join_name(namespace: str, name: str) -> str:
    return f"{namespace.rstrip('/')}/{name}"
