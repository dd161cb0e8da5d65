"""A service client that speaks RTPS to Fast DDS itself: LoadNode and UnloadNode without rclpy.

The launcher's only ROS need in a run of composable nodes is to call each container's
``_container/load_node``; rclpy, its message packages and a Fast DDS participant cost ~64 MB of
the launcher's memory for that. This module is the least of DDSI-RTPS 2.3 that such a call
needs, over UDPv4, as ROS 2 Jazzy's rmw_fastrtps (Fast DDS 2.14) expects it:

- **Participant discovery (SPDP)**: this participant is announced every few seconds, and to each
  participant the moment it is found; announcements are received and kept while their lease
  lasts. Where they go is what rmw_fastrtps sets up for the discovery range: SUBNET (the
  default, and SYSTEM_DEFAULT) multicast 239.255.0.1 at port 7400 + 250 * domain, received on a
  shared socket of that port too (and, in case this host routes no multicast, the unicast
  discovery ports of ids 0 to 3 on 127.0.0.1: Fast DDS's default initial peers); LOCALHOST the
  unicast discovery ports of participant ids 0 to 31 on 127.0.0.1 (7410 + 250 * domain + 2 * id:
  Fast DDS's initial peers with rmw_fastrtps's maxInitialPeersRange), no multicast. This
  participant takes the first free of those ports, so theirs reach it too.
- **Endpoint discovery (SEDP)**: the reliable builtin publications and subscriptions writers
  (every announcement kept, sent to each participant found) and readers (ACKNACK on HEARTBEAT).
  Announcements that do not name a container's service are acknowledged and not parsed.
- **A service client**: per service, a reliable writer of ``rq/<service>Request`` and a
  reliable reader of ``rr/<service>Reply`` (volatile, keep-last: rmw's services profile), with
  rmw_fastrtps's type names (``composition_interfaces::srv::dds_::LoadNode_Request_``). A
  request carries, as inline QoS (PID_RELATED_SAMPLE_IDENTITY), the GUID of this client's reply
  reader: the service answers with the request's sample identity (that GUID and the request's
  sequence number) as the reply's related sample identity, and answers only once its reply
  writer has matched that reader. So a service is *ready* when the container's request reader
  and reply writer are discovered and its participant has acknowledged this client's two
  endpoint announcements.

Robust by construction: every packet is parsed under one ``except`` that drops it (a truncated,
garbage or hostile datagram never reaches past the parser), state per remote participant is
bounded and ends with its lease, a wait is the caller's (``until``) and ``close`` ends the
thread and closes the sockets.

Used by the components part only where it is exactly what rclpy would do (``usable``).
"""

from __future__ import annotations

import os
import selectors
import socket
import struct
import threading
import time
from collections.abc import Callable, Mapping, Sequence

from mlaunch.parts.lean import FAST_DDS, USER_SETTINGS

TYPE_CHECKING = False  # mypy treats this name as typing.TYPE_CHECKING; typing costs ~4 ms
if TYPE_CHECKING:
    from typing import Any

# --- the wire ------------------------------------------------------------------------------

PROTOCOL = b"RTPS\x02\x03"
# Not eProsima's: Fast DDS must take this participant for another vendor's (no shared memory,
# no vendor-specific parameters expected). 0x01FF is unassigned in the OMG's list.
VENDOR = b"\x01\xff"
PB, DG, PG, D0, D1 = 7400, 250, 2, 0, 10  # the RTPS port mapping's defaults
MULTICAST = "239.255.0.1"
LOCALHOST_PEERS = 32  # rmw_fastrtps's maxInitialPeersRange for LOCALHOST
SUBNET_LOCAL_PEERS = 4  # Fast DDS's default maxInitialPeersRange
MAX_PARTICIPANT_ID = 120
LEASE = 20.0  # this participant's lease duration, as Fast DDS's default
ANNOUNCE = 3.0  # the period of its announcements (Fast DDS's)
HEARTBEAT = 0.5  # how often unacknowledged data is announced again
MAX_PARTICIPANTS = 4096  # remote participants kept at most (the oldest go first)
MAX_HISTORY = 64  # requests kept for resending, per client
MAX_DATAGRAM = 65507
POLL = 0.1  # how often a waiting call asks its ``until``
DATAGRAM_BUDGET = 60000  # what one datagram we send holds at most (Fast DDS takes 65500)
FRAGMENT = 16384  # a request larger than this goes as DATA_FRAG submessages of this size
MAX_SAMPLE = 64 << 20  # a request larger than this is refused (its parameters, not a file)

# submessage ids
PAD, ACKNACK, HEARTBEAT_ID, GAP, INFO_TS, INFO_SRC = 0x01, 0x06, 0x07, 0x08, 0x09, 0x0C
INFO_DST, NACK_FRAG, DATA, DATA_FRAG = 0x0E, 0x12, 0x15, 0x16
# parameter ids
PID_SENTINEL, PID_PAD = 0x0001, 0x0000
PID_LEASE, PID_DOMAIN_ID, PID_TOPIC, PID_TYPE = 0x0002, 0x000F, 0x0005, 0x0007
PID_PROTOCOL_VERSION, PID_VENDOR = 0x0015, 0x0016
PID_RELIABILITY, PID_DURABILITY, PID_HISTORY = 0x001A, 0x001D, 0x0040
PID_PARTITION = 0x0029
PID_UNICAST_LOCATOR, PID_DEFAULT_UNICAST, PID_METATRAFFIC_UNICAST = 0x002F, 0x0031, 0x0032
PID_PARTICIPANT_GUID, PID_ENDPOINT_GUID, PID_BUILTIN_ENDPOINTS = 0x0050, 0x005A, 0x0058
PID_KEY_HASH, PID_STATUS_INFO = 0x0070, 0x0071
PID_RELATED_SAMPLE_IDENTITY, PID_CUSTOM_RELATED_SAMPLE_IDENTITY = 0x0083, 0x800F
PID_ENTITY_NAME = 0x0062

LOCATOR_UDPv4 = 1
PL_CDR_LE = b"\x00\x03"
PL_CDR_BE = b"\x00\x02"

ENTITY_UNKNOWN = b"\x00\x00\x00\x00"
PARTICIPANT = b"\x00\x00\x01\xc1"
SPDP_WRITER, SPDP_READER = b"\x00\x01\x00\xc2", b"\x00\x01\x00\xc7"
PUB_WRITER, PUB_READER = b"\x00\x00\x03\xc2", b"\x00\x00\x03\xc7"
SUB_WRITER, SUB_READER = b"\x00\x00\x04\xc2", b"\x00\x00\x04\xc7"
# builtin endpoint set: participant announcer and detector, publications and subscriptions
# announcers and detectors
BUILTIN_ENDPOINTS = 0x3F
PUBLICATIONS_DETECTOR, SUBSCRIPTIONS_DETECTOR = 1 << 3, 1 << 5
# a user entity without key: writer 0x03, reader 0x04 (the reader bit rmw_fastrtps tests)
USER_WRITER, USER_READER = 0x03, 0x04

RELIABLE, VOLATILE, KEEP_LAST = 2, 0, 0
SN_UNKNOWN = (-1 << 32) | 0  # high -1, low 0: SequenceNumber_t::unknown()


def _sn(high: int, low: int) -> int:
    return (high << 32) | low


def _pack_sn(value: int) -> bytes:
    return struct.pack("<iI", value >> 32, value & 0xFFFFFFFF)


def _time(seconds: float) -> bytes:
    whole = int(seconds)
    return struct.pack("<iI", whole, int((seconds - whole) * (1 << 32)) & 0xFFFFFFFF)


def _param(pid: int, value: bytes) -> bytes:
    pad = -len(value) % 4
    return struct.pack("<HH", pid, len(value) + pad) + value + bytes(pad)


def _string(value: str) -> bytes:
    data = value.encode("utf-8") + b"\x00"
    return struct.pack("<I", len(data)) + data


def _locator(address: str, port: int) -> bytes:
    return struct.pack("<iI", LOCATOR_UDPv4, port) + bytes(12) + socket.inet_aton(address)


def parameter_list(data: bytes, little: bool) -> dict[int, list[bytes]]:
    """A ParameterList's values by parameter id (a repeated id keeps each value, in order)."""
    fmt = "<HH" if little else ">HH"
    out: dict[int, list[bytes]] = {}
    pos, end = 0, len(data)
    while pos + 4 <= end:
        pid, size = struct.unpack_from(fmt, data, pos)
        pos += 4
        if pid == PID_SENTINEL:
            return out
        if pos + size > end:
            raise ValueError(f"parameter {pid:#x} of {size} bytes past the end")
        if pid != PID_PAD:
            out.setdefault(pid & 0x3FFF if pid & 0x4000 else pid, []).append(data[pos : pos + size])
        pos += size
    raise ValueError("a parameter list without its sentinel")


def _text(value: bytes, little: bool) -> str:
    (size,) = struct.unpack_from("<I" if little else ">I", value, 0)
    if size == 0 or 4 + size > len(value):
        raise ValueError("a string past its parameter")
    return value[4 : 4 + size - 1].decode("utf-8")


def _locators(values: list[bytes], little: bool) -> list[tuple[str, int]]:
    out = []
    for value in values:
        kind, port = struct.unpack_from("<iI" if little else ">iI", value, 0)
        if kind == LOCATOR_UDPv4 and 0 < port < 65536 and len(value) >= 24:
            out.append((socket.inet_ntoa(value[20:24]), port))
    return out


# --- what the client knows of the others ---------------------------------------------------


class Remote:
    """A remote participant: where it listens, its lease, its endpoints of interest."""

    __slots__ = (
        "acked",
        "builtin",
        "default",
        "lease",
        "metatraffic",
        "offers",
        "prefix",
        "seen",
    )

    def __init__(self, prefix: bytes) -> None:
        self.prefix = prefix
        self.metatraffic: list[tuple[str, int]] = []
        self.default: list[tuple[str, int]] = []
        self.lease = LEASE
        self.seen = time.monotonic()
        self.builtin = 0
        self.offers = 0  # heartbeats in a row its SEDP readers did not acknowledge
        # what its SEDP readers acknowledged of ours: entity -> first sequence number not acked
        self.acked: dict[bytes, int] = {PUB_WRITER: 1, SUB_WRITER: 1}


class Endpoint:
    """A remote reader or writer on a topic of one of our clients."""

    __slots__ = ("addresses", "guid", "publication", "reliable", "topic", "type")

    def __init__(
        self, guid: bytes, topic: str, type: str, reliable: bool, addresses: list[tuple[str, int]]
    ) -> None:
        self.guid = guid
        self.topic = topic
        self.type = type
        self.reliable = reliable
        self.addresses = addresses
        self.publication = False  # a writer (True) or a reader


class ReaderState:
    """What a reliable reader received of one remote writer: ``base`` is the first sequence
    number not received, ``above`` those received past it (bounded)."""

    __slots__ = ("above", "base", "count")

    def __init__(self) -> None:
        # From the first: a writer answers what a reader may not have with a GAP.
        self.base = 1
        self.above: set[int] = set()
        self.count = 0

    def received(self, sn: int) -> bool:
        """Note ``sn``; False when it was received before."""
        if sn < self.base or sn in self.above:
            return False
        self.above.add(sn)
        while self.base in self.above:
            self.above.discard(self.base)
            self.base += 1
        if len(self.above) > 4096:  # a writer that skips forever: forget what is far behind
            self.above = {s for s in self.above if s > max(self.above) - 1024}
        return True

    def skip(self, first: int, last: int) -> None:
        """Sequence numbers ``first``..``last`` will never come (GAP, or below a HEARTBEAT)."""
        if first <= self.base <= last:
            self.base = last + 1
        elif self.base < first:
            self.above.update(range(first, min(last, first + 255) + 1))
        self.above = {s for s in self.above if s >= self.base}
        while self.base in self.above:
            self.above.discard(self.base)
            self.base += 1

    def missing(self, last: int) -> list[int]:
        return [s for s in range(self.base, min(last, self.base + 255) + 1) if s not in self.above]


class Matched:
    """A remote reader matched with a client's writer, and the first sequence number it has
    not acknowledged."""

    __slots__ = ("acked", "endpoint")

    def __init__(self, endpoint: Endpoint) -> None:
        self.endpoint = endpoint
        self.acked = 1


class Waiter:
    """A request's reply, set by the participant's thread."""

    __slots__ = ("event", "reply")

    def __init__(self) -> None:
        self.event = threading.Event()
        self.reply: bytes | None = None


class Client:
    """One service's request writer and reply reader, and the requests waiting for answers."""

    __slots__ = (
        "history",
        "pub_sn",
        "reader",
        "readers",
        "reply_type",
        "request_type",
        "service",
        "sn",
        "sub_sn",
        "waiting",
        "writer",
        "writers",
    )

    def __init__(self, service: str, kind: str, number: int, prefix: bytes) -> None:
        self.service = service
        self.request_type = f"composition_interfaces::srv::dds_::{kind}_Request_"
        self.reply_type = f"composition_interfaces::srv::dds_::{kind}_Response_"
        key = number.to_bytes(3, "big")
        self.writer = key + bytes((USER_WRITER,))
        self.reader = key + bytes((USER_READER,))
        self.sn = 0
        # sent requests by sequence number: their DATA (or DATA_FRAG) submessages, kept until
        # every reader acknowledged them
        self.history: dict[int, list[bytes]] = {}
        self.readers: dict[bytes, Matched] = {}  # matched remote readers of the requests
        self.writers: dict[bytes, Endpoint] = {}  # matched remote writers of the replies
        self.waiting: dict[int, Waiter] = {}  # sn -> the thread waiting for its reply
        self.pub_sn = 0  # our announcements of the two endpoints (their SEDP sequence numbers)
        self.sub_sn = 0


def request_topic(service: str) -> str:
    return f"rq{service}Request"


def reply_topic(service: str) -> str:
    return f"rr{service}Reply"


# --- when it may be used --------------------------------------------------------------------

# The user configures Fast DDS (profiles, transports, a discovery server, peers): its
# participants may not listen where this client looks.
FAST_DDS_SETTINGS = (*USER_SETTINGS, "FASTDDS_ENVIRONMENT_FILE", "ROS_STATIC_PEERS")
LOADER = "MLAUNCH_LOADER"


def discovery_range(environ: Mapping[str, str]) -> str | None:
    """The discovery range rcl (Jazzy) makes of ``environ``: "LOCALHOST" or "SUBNET"; None
    when it is one this client does not serve (OFF, a value rcl warns about)."""
    if environ.get("ROS_LOCALHOST_ONLY") == "1":
        return "LOCALHOST"
    value = environ.get("ROS_AUTOMATIC_DISCOVERY_RANGE", "")
    if value in ("", "SUBNET", "SYSTEM_DEFAULT"):
        return "SUBNET"
    if value == "LOCALHOST":
        return "LOCALHOST"
    return None


def unusable(environ: Mapping[str, str], others: Sequence[Mapping[str, str]]) -> str:
    """Why this client may not stand in for rclpy with the launcher's ``environ`` and the
    launched processes' ``others`` ("" when it may): only Fast DDS as every side's RMW, its
    defaults (no profile, transport, discovery server, static peers, security), one domain."""
    choice = environ.get(LOADER, "")
    if choice == "rclpy":
        return f"{LOADER}=rclpy"
    if choice not in ("", "rtps"):
        return f"{LOADER}={choice!r} is not 'rtps' or 'rclpy'"
    if discovery_range(environ) is None:
        return f"ROS_AUTOMATIC_DISCOVERY_RANGE={environ.get('ROS_AUTOMATIC_DISCOVERY_RANGE')!r}"
    domain = environ.get("ROS_DOMAIN_ID", "").strip()
    for env in (environ, *others):
        rmw = env.get("RMW_IMPLEMENTATION", "")
        if rmw not in FAST_DDS:
            return f"RMW_IMPLEMENTATION={rmw}"
        for name in FAST_DDS_SETTINGS:
            if env.get(name):
                return f"{name} is set"
        for name, value in env.items():
            if name.startswith("ROS_SECURITY_") and value:
                return f"{name} is set"
        if env.get("ROS_DOMAIN_ID", "").strip() != domain:
            return "the processes run in another ROS_DOMAIN_ID"
        if discovery_range(env) != discovery_range(environ):
            return "the processes discover in another range"
    return ""


def _interface_addresses() -> list[str]:
    """This host's IPv4 addresses but loopback's (what Fast DDS announces as its locators)."""
    import fcntl

    found: list[str] = []
    probe = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        for _, name in socket.if_nameindex():
            request = struct.pack("256s", name.encode()[:15])
            try:
                answer = fcntl.ioctl(probe.fileno(), 0x8915, request)  # SIOCGIFADDR
            except OSError:
                continue
            address = socket.inet_ntoa(answer[20:24])
            if not address.startswith("127.") and address not in found:
                found.append(address)
    finally:
        probe.close()
    return found


# --- the participant ------------------------------------------------------------------------


class Participant:
    """This process's RTPS participant: discovery, the service clients, one thread.

    ``domain``: the ROS domain; ``scope``: "LOCALHOST" or "SUBNET" (``discovery_range``).
    """

    def __init__(self, domain: int, scope: str, name: str = "mlaunch") -> None:
        self.domain = domain
        self.scope = scope
        self.name = name
        self.prefix = VENDOR + os.getpid().to_bytes(4, "big") + os.urandom(6)
        self.lock = threading.Lock()
        self.remotes: dict[bytes, Remote] = {}
        self.clients: dict[str, Client] = {}
        self.by_entity: dict[bytes, Client] = {}
        self.states: dict[bytes, ReaderState] = {}  # remote writer guid -> what we received
        # the containers' service endpoints discovered, by guid
        self.endpoints: dict[bytes, Endpoint] = {}
        # our SEDP announcements: (writer entity) -> [(sn, DATA submessage)]
        self.announced: dict[bytes, list[tuple[int, bytes]]] = {PUB_WRITER: [], SUB_WRITER: []}
        self.count = 0
        self.closed = threading.Event()
        self.error = ""  # the last unexpected failure it lived through (the tests look)
        self.addresses = ["127.0.0.1"]
        if scope == "SUBNET":
            self.addresses = _interface_addresses() or ["127.0.0.1"]
        self.unicast, self.port = self._bind_unicast()
        self.multicast = self._bind_multicast() if scope == "SUBNET" else None
        self.spdp = self._spdp()
        self._thread = threading.Thread(target=self._run, name="rtps", daemon=True)
        self._thread.start()

    # --- sockets ---

    def _bind_unicast(self) -> tuple[socket.socket, int]:
        """The first free unicast discovery port of a participant id (others then reach it as
        one of their initial peers); the socket takes user data too."""
        base = PB + DG * self.domain + D1
        last: OSError | None = None
        for pid in range(MAX_PARTICIPANT_ID):
            sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
            try:
                sock.bind(("0.0.0.0", base + PG * pid))
            except OSError as e:
                sock.close()
                last = e
                continue
            _buffers(sock)
            sock.setblocking(False)
            return sock, base + PG * pid
        raise OSError(f"no free RTPS port from {base} for domain {self.domain}: {last}")

    def _bind_multicast(self) -> socket.socket:
        sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        if hasattr(socket, "SO_REUSEPORT"):
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEPORT, 1)
        sock.bind(("", PB + DG * self.domain + D0))
        # The group on every interface, as Fast DDS joins it (a container on another subnet
        # of this host is heard too).
        for address in ["0.0.0.0", *self.addresses]:
            group = socket.inet_aton(MULTICAST) + socket.inet_aton(address)
            try:
                sock.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP, group)
            except OSError:
                pass  # joined already (the default interface), or no multicast there
        _buffers(sock)
        sock.setblocking(False)
        self.unicast.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, 1)
        return sock

    def _send(self, data: bytes, addresses: list[tuple[str, int]]) -> None:
        for address in addresses:
            if address[0] == MULTICAST:
                self._send_multicast(data, address)
                continue
            try:
                self.unicast.sendto(data, address)
            except OSError:
                pass  # a peer gone, a full buffer: reliability sends again

    def _send_multicast(self, data: bytes, address: tuple[str, int]) -> None:
        """Out of every interface, as Fast DDS sends its announcements (only this participant's
        thread, and ``close`` after it, send to the group)."""
        for interface in self.addresses:
            try:
                self.unicast.setsockopt(
                    socket.IPPROTO_IP, socket.IP_MULTICAST_IF, socket.inet_aton(interface)
                )
                self.unicast.sendto(data, address)
            except OSError:
                pass  # no multicast out of this one: the others, and unicast, still go

    def _peers(self) -> list[tuple[str, int]]:
        """Where this participant's periodic announcement goes: LOCALHOST, the discovery ports
        of participant ids 0 to 31 on this host; SUBNET, the multicast group, and (should this
        host not route multicast) the ports of Fast DDS's default initial peers, ids 0 to 3."""
        base = PB + DG * self.domain + D1
        count = LOCALHOST_PEERS if self.scope == "LOCALHOST" else SUBNET_LOCAL_PEERS
        local = [
            ("127.0.0.1", base + PG * pid) for pid in range(count) if base + PG * pid != self.port
        ]
        if self.scope == "SUBNET":
            return [(MULTICAST, PB + DG * self.domain + D0), *local]
        return local

    # --- messages ---

    def _header(self, destination: bytes | None = None) -> bytes:
        head = PROTOCOL + VENDOR + self.prefix
        if destination is not None:
            head += struct.pack("<BBH", INFO_DST, 1, 12) + destination
        return head

    def _spdp(self) -> bytes:
        guid = self.prefix + PARTICIPANT
        params = b"".join(
            (
                _param(PID_PROTOCOL_VERSION, b"\x02\x03"),
                _param(PID_VENDOR, VENDOR),
                _param(PID_PARTICIPANT_GUID, guid),
                _param(PID_DOMAIN_ID, struct.pack("<I", self.domain)),
                *(_param(PID_METATRAFFIC_UNICAST, _locator(a, self.port)) for a in self.addresses),
                *(_param(PID_DEFAULT_UNICAST, _locator(a, self.port)) for a in self.addresses),
                _param(PID_LEASE, _time(LEASE)),
                _param(PID_BUILTIN_ENDPOINTS, struct.pack("<I", BUILTIN_ENDPOINTS)),
                _param(PID_ENTITY_NAME, _string(self.name)),
                struct.pack("<HH", PID_SENTINEL, 0),
            )
        )
        inline = _param(PID_KEY_HASH, guid) + struct.pack("<HH", PID_SENTINEL, 0)
        return self._header() + _data(
            SPDP_READER, SPDP_WRITER, 1, PL_CDR_LE + b"\0\0" + params, inline
        )

    def _announce(self, client: Client, writer: bool) -> int:
        """Our SEDP announcement of one endpoint of ``client`` (its sequence number)."""
        if writer:
            return self.endpoint(
                client.writer, request_topic(client.service), client.request_type, True
            )
        return self.endpoint(client.reader, reply_topic(client.service), client.reply_type, False)

    def endpoint(self, entity: bytes, topic: str, type_name: str, writer: bool) -> int:
        """Announce a reliable, volatile endpoint (a writer, or a reader) of this participant:
        its SEDP sequence number."""
        guid = self.prefix + entity
        params = b"".join(
            (
                _param(PID_ENDPOINT_GUID, guid),
                _param(PID_PARTICIPANT_GUID, self.prefix + PARTICIPANT),
                _param(PID_TOPIC, _string(topic)),
                _param(PID_TYPE, _string(type_name)),
                _param(PID_RELIABILITY, struct.pack("<I", RELIABLE) + _time(0.1)),
                _param(PID_DURABILITY, struct.pack("<I", VOLATILE)),
                _param(PID_HISTORY, struct.pack("<Ii", KEEP_LAST, 10)),
                *(_param(PID_UNICAST_LOCATOR, _locator(a, self.port)) for a in self.addresses),
                struct.pack("<HH", PID_SENTINEL, 0),
            )
        )
        inline = _param(PID_KEY_HASH, guid) + struct.pack("<HH", PID_SENTINEL, 0)
        source = PUB_WRITER if writer else SUB_WRITER
        history = self.announced[source]
        sn = len(history) + 1
        reader = PUB_READER if writer else SUB_READER
        history.append((sn, _data(reader, source, sn, PL_CDR_LE + b"\0\0" + params, inline)))
        return sn

    def _heartbeat(self, reader: bytes, writer: bytes, first: int, last: int) -> bytes:
        self.count += 1
        return (
            struct.pack("<BBH", HEARTBEAT_ID, 1, 28)
            + reader
            + writer
            + (_pack_sn(first) + _pack_sn(last) + struct.pack("<I", self.count))
        )

    def _acknack(self, reader: bytes, writer: bytes, state: ReaderState, last: int) -> bytes:
        missing = state.missing(last)
        base = state.base
        bits = (max(missing) - base + 1) if missing else 0
        words = [0] * ((bits + 31) // 32)
        for s in missing:
            i = s - base
            words[i // 32] |= 1 << (31 - i % 32)
        state.count += 1
        body = (
            reader
            + writer
            + _pack_sn(base)
            + struct.pack(f"<I{len(words)}I", bits, *words)
            + struct.pack("<I", state.count)
        )
        flags = 1 | (0 if missing else 2)
        return struct.pack("<BBH", ACKNACK, flags, len(body)) + body

    # --- the thread ---

    def _run(self) -> None:
        selector = selectors.DefaultSelector()
        selector.register(self.unicast, selectors.EVENT_READ)
        if self.multicast is not None:
            selector.register(self.multicast, selectors.EVENT_READ)
        next_announce = 0.0
        announced = 0
        next_beat = 0.0
        try:
            while not self.closed.is_set():
                now = time.monotonic()
                try:
                    if now >= next_announce:
                        announced += 1
                        # quick at first (a container just started finds us at once), then slow
                        next_announce = now + (0.1 * announced if announced < 5 else ANNOUNCE)
                        self._send(self.spdp, self._peers())
                        self._expire(now)
                    if now >= next_beat:
                        next_beat = now + HEARTBEAT
                        with self.lock:
                            self._beat()
                except Exception as e:  # the loads wait on this thread: it lives on
                    self.error = f"{type(e).__name__}: {e}"
                wait = max(0.0, min(next_announce, next_beat) - time.monotonic())
                for key, _ in selector.select(min(wait, 0.2)):
                    self._drain(key.fileobj)  # type: ignore[arg-type]
        finally:
            selector.close()

    def _drain(self, sock: socket.socket) -> None:
        for _ in range(256):  # bounded: the timers still run under a flood
            try:
                data, _ = sock.recvfrom(MAX_DATAGRAM)
            except OSError:  # nothing more to read (or the socket closed under us)
                return
            self.receive(data)

    def receive(self, data: bytes) -> bool:
        """Take one datagram; False when it was dropped (not RTPS, or not as it should be)."""
        try:
            with self.lock:
                self._message(data)
        except (ValueError, struct.error, IndexError, KeyError):  # UnicodeDecodeError too
            return False
        except Exception as e:  # a case the parser missed: dropped all the same
            self.error = f"{type(e).__name__}: {e}"
            return False
        return True

    def _message(self, data: bytes) -> None:
        if len(data) < 20 or data[:4] != b"RTPS" or data[4] != 2:
            return
        source = data[8:20]
        if source == self.prefix:
            return  # our own multicast, looped back
        destination = b""
        pos = 20
        end = len(data)
        while pos + 4 <= end:
            kind, flags = data[pos], data[pos + 1]
            little = bool(flags & 1)
            (size,) = struct.unpack_from("<H" if little else ">H", data, pos + 2)
            body_at = pos + 4
            if size == 0 and kind not in (PAD, INFO_TS):
                size = end - body_at  # the last submessage
            if body_at + size > end:
                return
            body = data[body_at : body_at + size]
            pos = body_at + size
            if kind == INFO_DST:
                destination = body[:12]
            elif kind == INFO_SRC:
                source = body[8:20]
            elif destination not in (b"", bytes(12), self.prefix):
                continue  # for another participant
            elif kind == DATA:
                self._data(source, flags, body, little)
            elif kind == HEARTBEAT_ID:
                self._on_heartbeat(source, flags, body, little)
            elif kind == ACKNACK:
                self._on_acknack(source, body, little)
            elif kind == GAP:
                self._on_gap(source, body, little)
            elif kind == NACK_FRAG:
                self._on_nack_frag(source, body, little)
            elif kind == DATA_FRAG:
                self._on_data_frag(source, body, little)

    def _data(self, source: bytes, flags: int, body: bytes, little: bool) -> None:
        i = "<" if little else ">"
        (to_qos,) = struct.unpack_from(f"{i}H", body, 2)
        reader, writer = body[4:8], body[8:12]
        high, low = struct.unpack_from(f"{i}iI", body, 12)
        sn = _sn(high, low)
        at = 4 + to_qos
        inline: dict[int, list[bytes]] = {}
        if flags & 2:  # inline QoS
            inline = parameter_list(body[at:], little)
            while True:  # the payload follows the list's sentinel
                pid, size = struct.unpack_from(f"{i}HH", body, at)
                at += 4 + (0 if pid == PID_SENTINEL else size)
                if pid == PID_SENTINEL:
                    break
        payload = body[at:] if flags & (4 | 8) else b""
        guid = source + writer
        if writer == SPDP_WRITER:
            self._participant(source, payload, inline)
            return
        if writer in (PUB_WRITER, SUB_WRITER):
            if source not in self.remotes:
                return
            state = self.states.setdefault(guid, ReaderState())
            if state.received(sn):
                self._endpoint(source, writer == PUB_WRITER, payload, inline)
            return
        client = self._reply_client(guid, reader)
        if client is None:
            return
        state = self.states.setdefault(guid, ReaderState())
        if not state.received(sn):
            return
        related = inline.get(PID_RELATED_SAMPLE_IDENTITY) or inline.get(
            PID_CUSTOM_RELATED_SAMPLE_IDENTITY
        )
        if not related or len(related[0]) < 24:
            return
        identity = related[0]
        if identity[:16] not in (self.prefix + client.reader, self.prefix + client.writer):
            return  # another client's answer
        high, low = struct.unpack_from(f"{i}iI", identity, 16)
        waiter = client.waiting.get(_sn(high, low))
        if waiter is not None and waiter.reply is None:
            waiter.reply = bytes(payload)
            waiter.event.set()

    def _on_data_frag(self, source: bytes, body: bytes, little: bool) -> None:
        """A sample in fragments: no container's endpoint or answer is that large, so it is
        noted as received (an endpoint announcement not asked for again), never assembled."""
        writer = body[8:12]
        if writer in (PUB_WRITER, SUB_WRITER) and source in self.remotes:
            high, low = struct.unpack_from("<iI" if little else ">iI", body, 12)
            self.states.setdefault(source + writer, ReaderState()).received(_sn(high, low))

    def _reply_client(self, guid: bytes, reader: bytes) -> Client | None:
        client = self.by_entity.get(reader)
        if client is not None and guid in client.writers:
            return client
        for client in self.clients.values():
            if guid in client.writers:
                return client
        return None

    def _participant(self, source: bytes, payload: bytes, inline: dict[int, list[bytes]]) -> None:
        status = inline.get(PID_STATUS_INFO)
        if status and status[0][-1] & 3:  # disposed or unregistered: it left
            self._forget(source)
            return
        if len(payload) < 4 or payload[:2] not in (PL_CDR_LE, PL_CDR_BE):
            return
        little = payload[:2] == PL_CDR_LE
        params = parameter_list(payload[4:], little)
        guid = params.get(PID_PARTICIPANT_GUID, [source + PARTICIPANT])[0]
        if guid[:12] != source:
            return
        domain = params.get(PID_DOMAIN_ID)
        if domain and struct.unpack("<I" if little else ">I", domain[0][:4])[0] != self.domain:
            return
        remote = self.remotes.get(source)
        new = remote is None
        if remote is None:
            if len(self.remotes) >= MAX_PARTICIPANTS:
                oldest = min(self.remotes.values(), key=lambda r: r.seen)
                self._forget(oldest.prefix)
            remote = self.remotes[source] = Remote(source)
        remote.seen = time.monotonic()
        remote.metatraffic = _local(_locators(params.get(PID_METATRAFFIC_UNICAST, []), little))
        remote.default = _local(_locators(params.get(PID_DEFAULT_UNICAST, []), little))
        lease = params.get(PID_LEASE)
        if lease:
            seconds, _ = struct.unpack("<iI" if little else ">iI", lease[0][:8])
            remote.lease = max(1.0, min(float(seconds), 3600.0))
        builtin = params.get(PID_BUILTIN_ENDPOINTS)
        if builtin:
            remote.builtin = struct.unpack("<I" if little else ">I", builtin[0][:4])[0]
        if new and remote.metatraffic:
            # tell it of us now, and what we have announced so far
            self._send(self.spdp, remote.metatraffic)
            self._offer(remote)

    def _offer(self, remote: Remote) -> None:
        """Our SEDP announcements it has not acknowledged, and a heartbeat of each writer."""
        parts: list[bytes] = []
        for writer, reader, bit in (
            (PUB_WRITER, PUB_READER, PUBLICATIONS_DETECTOR),
            (SUB_WRITER, SUB_READER, SUBSCRIPTIONS_DETECTOR),
        ):
            if not remote.builtin & bit:
                continue
            history = self.announced[writer]
            for sn, data in history:
                if sn >= remote.acked[writer]:
                    parts.append(data)
            parts.append(self._heartbeat(reader, writer, 1, len(history)))
        if parts:
            self._deliver(remote.prefix, parts, b"", remote.metatraffic)

    def _endpoint(
        self, source: bytes, publication: bool, payload: bytes, inline: dict[int, list[bytes]]
    ) -> None:
        """A remote endpoint announced (or gone): matched when it is one of our services'."""
        key = inline.get(PID_KEY_HASH)
        status = inline.get(PID_STATUS_INFO)
        if status and status[0][-1] & 3:
            if key:
                self._unmatch(key[0][:16])
            return
        if b"_container/" not in payload:
            return  # not a container's service: nothing to parse
        if len(payload) < 4 or payload[:2] not in (PL_CDR_LE, PL_CDR_BE):
            return
        little = payload[:2] == PL_CDR_LE
        params = parameter_list(payload[4:], little)
        guid = params.get(PID_ENDPOINT_GUID, key or [b""])[0][:16]
        if len(guid) != 16 or guid[:12] != source:
            return
        topic = _text(params[PID_TOPIC][0], little)
        type_name = _text(params[PID_TYPE][0], little)
        for partition in params.get(PID_PARTITION, []):
            (count,) = struct.unpack_from("<I" if little else ">I", partition, 0)
            if count and _text(partition[4:], little) != "":
                return  # a partition of its own: not ours (rmw sets none)
        reliable = False
        reliability = params.get(PID_RELIABILITY)
        if reliability:
            (kind,) = struct.unpack_from("<I" if little else ">I", reliability[0], 0)
            reliable = kind == RELIABLE
        elif publication:
            reliable = True  # a writer's default
        remote = self.remotes.get(source)
        if remote is None:
            return
        addresses = _local(_locators(params.get(PID_UNICAST_LOCATOR, []), little))
        endpoint = Endpoint(guid, topic, type_name, reliable, addresses or remote.default)
        endpoint.publication = publication
        # kept while its participant lives: a client made later (a load a timer sends into a
        # container that has run for a while) matches it then
        self.endpoints[guid] = endpoint
        for client in self.clients.values():
            self._match(client, endpoint)

    def _match(self, client: Client, endpoint: Endpoint) -> None:
        if endpoint.publication:
            if (
                endpoint.topic == reply_topic(client.service)
                and endpoint.type == client.reply_type
                and endpoint.reliable
            ):
                client.writers[endpoint.guid] = endpoint
        elif (
            endpoint.topic == request_topic(client.service) and endpoint.type == client.request_type
        ):
            client.readers[endpoint.guid] = Matched(endpoint)
            self._resend(client, endpoint.guid)

    def _unmatch(self, guid: bytes) -> None:
        self.endpoints.pop(guid, None)
        for client in self.clients.values():
            client.writers.pop(guid, None)
            client.readers.pop(guid, None)
        self.states.pop(guid, None)

    def _forget(self, prefix: bytes) -> None:
        self.remotes.pop(prefix, None)
        tables: list[dict[bytes, Any]] = [self.states, self.endpoints]
        for client in self.clients.values():
            tables += (client.writers, client.readers)
        for table in tables:
            for guid in [g for g in table if g[:12] == prefix]:
                del table[guid]

    def _expire(self, now: float) -> None:
        with self.lock:
            for remote in list(self.remotes.values()):
                if now - remote.seen > remote.lease:
                    self._forget(remote.prefix)

    def _on_heartbeat(self, source: bytes, flags: int, body: bytes, little: bool) -> None:
        i = "<" if little else ">"
        reader, writer = body[0:4], body[4:8]
        first = _sn(*struct.unpack_from(f"{i}iI", body, 8))
        last = _sn(*struct.unpack_from(f"{i}iI", body, 16))
        guid = source + writer
        remote = self.remotes.get(source)
        if remote is None:
            return
        if writer in (PUB_WRITER, SUB_WRITER):
            reader = PUB_READER if writer == PUB_WRITER else SUB_READER
        else:
            client = self._reply_client(guid, reader)
            if client is None:
                return
            reader = client.reader
        state = self.states.setdefault(guid, ReaderState())
        if state.base < first:  # what the writer no longer has will not come
            state.skip(state.base, first - 1)
        if flags & 2 and not state.missing(last):
            return  # final, and nothing is missing: no answer wanted
        addresses = remote.metatraffic if writer in (PUB_WRITER, SUB_WRITER) else remote.default
        # the ACKNACK's reader is ours, its writer theirs
        message = self._header(source) + self._acknack(reader, writer, state, last)
        self._send(message, addresses)

    def _on_gap(self, source: bytes, body: bytes, little: bool) -> None:
        i = "<" if little else ">"
        writer = body[4:8]
        start = _sn(*struct.unpack_from(f"{i}iI", body, 8))
        base = _sn(*struct.unpack_from(f"{i}iI", body, 16))
        (bits,) = struct.unpack_from(f"{i}I", body, 24)
        state = self.states.get(source + writer)
        if state is None:
            return
        state.skip(start, base - 1)
        words = struct.unpack_from(f"{i}{(min(bits, 256) + 31) // 32}I", body, 28)
        for n in range(min(bits, 256)):
            if words[n // 32] & (1 << (31 - n % 32)):
                state.skip(base + n, base + n)

    def _on_acknack(self, source: bytes, body: bytes, little: bool) -> None:
        i = "<" if little else ">"
        reader, writer = body[0:4], body[4:8]
        base = _sn(*struct.unpack_from(f"{i}iI", body, 8))
        (bits,) = struct.unpack_from(f"{i}I", body, 16)
        words = struct.unpack_from(f"{i}{(min(bits, 256) + 31) // 32}I", body, 20)
        wanted = [base + n for n in range(min(bits, 256)) if words[n // 32] & (1 << (31 - n % 32))]
        remote = self.remotes.get(source)
        if remote is None:
            return
        if writer in (PUB_WRITER, SUB_WRITER):
            remote.acked[writer] = max(remote.acked[writer], base)
            history = dict(self.announced[writer])
            resend = [history[s] for s in wanted if s in history]
            if resend:
                target = PUB_READER if writer == PUB_WRITER else SUB_READER
                beat = self._heartbeat(target, writer, 1, len(history))
                self._deliver(source, resend, beat, remote.metatraffic)
            return
        client = self.by_entity.get(writer)
        if client is None:
            return
        entry = client.readers.get(source + reader)
        if entry is None:
            return
        entry.acked = max(entry.acked, base)
        self._resend_requests(client, source + reader, wanted)
        self._trim(client)

    def _resend_requests(self, client: Client, guid: bytes, wanted: list[int]) -> None:
        """Send reader ``guid`` the requests ``wanted`` again (a GAP for those forgotten)."""
        entry = client.readers.get(guid)
        if entry is None or not wanted:
            return
        reader = guid[12:]
        parts = [part for s in wanted if s in client.history for part in client.history[s]]
        for s in wanted:  # dropped from the history: the reader need not wait for them
            if s not in client.history and s <= client.sn:
                parts.append(_gap(reader, client.writer, s))
        if parts:
            beat = self._heartbeat(reader, client.writer, self._first(client), client.sn)
            self._deliver(guid[:12], parts, beat, entry.endpoint.addresses)

    def _on_nack_frag(self, source: bytes, body: bytes, little: bool) -> None:
        """A reader misses fragments of a request: all of that request goes again."""
        i = "<" if little else ">"
        reader, writer = body[0:4], body[4:8]
        sn = _sn(*struct.unpack_from(f"{i}iI", body, 8))
        client = self.by_entity.get(writer)
        if client is not None:
            self._resend_requests(client, source + reader, [sn])

    def _deliver(
        self, prefix: bytes, parts: list[bytes], tail: bytes, addresses: list[tuple[str, int]]
    ) -> None:
        """``parts`` (submessages) to participant ``prefix``, as few datagrams as hold them,
        ``tail`` (a heartbeat) at the end of the last."""
        head = self._header(prefix)
        datagram = [head]
        size = len(head)
        for part in parts:
            if size + len(part) > DATAGRAM_BUDGET and len(datagram) > 1:
                self._send(b"".join(datagram), addresses)
                datagram, size = [head], len(head)
            datagram.append(part)
            size += len(part)
        datagram.append(tail)
        self._send(b"".join(datagram), addresses)

    def _first(self, client: Client) -> int:
        return min(client.history) if client.history else client.sn + 1

    def _trim(self, client: Client) -> None:
        """Forget requests every matched reader acknowledged (and the oldest past the bound)."""
        if not client.history:
            return
        acked = min((e.acked for e in client.readers.values()), default=client.sn + 1)
        for sn in [s for s in client.history if s < acked]:
            del client.history[sn]
        while len(client.history) > MAX_HISTORY:
            del client.history[min(client.history)]

    def _resend(self, client: Client, guid: bytes) -> None:
        """A reader matched late: the heartbeat tells it what there is (it asks for it)."""
        entry = client.readers[guid]
        beat = self._heartbeat(guid[12:], client.writer, self._first(client), client.sn)
        self._send(self._header(guid[:12]) + beat, entry.endpoint.addresses)

    def _beat(self) -> None:
        """Heartbeats of what is not acknowledged yet (the lock held)."""
        for remote in self.remotes.values():
            if any(remote.acked[w] <= len(self.announced[w]) for w in (PUB_WRITER, SUB_WRITER)):
                # one that does not acknowledge (unreachable from here): every 4 s after 5 s
                remote.offers += 1
                if remote.offers <= 10 or remote.offers % 8 == 0:
                    self._offer(remote)
            else:
                remote.offers = 0
        for client in self.clients.values():
            for guid, entry in client.readers.items():
                if entry.acked <= client.sn:
                    beat = self._heartbeat(guid[12:], client.writer, self._first(client), client.sn)
                    self._send(self._header(guid[:12]) + beat, entry.endpoint.addresses)

    # --- the clients' side (any thread) ---

    def client(self, service: str, kind: str) -> Client:
        """The client of ``service`` (``kind``: "LoadNode" or "UnloadNode"), made and announced
        at first use; every thread's calls to one service share it."""
        with self.lock:
            key = f"{kind} {service}"
            client = self.clients.get(key)
            if client is None:
                client = Client(service, kind, len(self.clients) + 1, self.prefix)
                self.clients[key] = client
                self.by_entity[client.writer] = client
                self.by_entity[client.reader] = client
                # the reply reader first: the service answers only once it has matched it
                client.sub_sn = self._announce(client, writer=False)
                client.pub_sn = self._announce(client, writer=True)
                for endpoint in self.endpoints.values():
                    self._match(client, endpoint)
                for remote in self.remotes.values():
                    self._offer(remote)
            return client

    def ready(self, client: Client) -> bool:
        """The service is there: its request reader and reply writer are matched, and their
        participant has acknowledged both of the client's endpoints."""
        with self.lock:
            for guid in client.readers:
                remote = self.remotes.get(guid[:12])
                if remote is None or not any(w[:12] == guid[:12] for w in client.writers):
                    continue
                if remote.acked[PUB_WRITER] > client.pub_sn and (
                    remote.acked[SUB_WRITER] > client.sub_sn
                ):
                    return True
            return False

    def call(self, client: Client, payload: bytes, until: Callable[[], bool]) -> bytes | None:
        """Send a request and wait for its reply's payload; None once ``until()``."""
        if len(payload) > MAX_SAMPLE:
            raise ValueError(f"a request of {len(payload)} bytes (at most {MAX_SAMPLE})")
        waiter = Waiter()
        with self.lock:
            client.sn += 1
            sn = client.sn
            inline = _param(
                PID_RELATED_SAMPLE_IDENTITY, self.prefix + client.reader + _pack_sn(SN_UNKNOWN)
            ) + struct.pack("<HH", PID_SENTINEL, 0)
            if len(payload) > FRAGMENT:
                data = _fragments(ENTITY_UNKNOWN, client.writer, sn, payload, inline)
            else:
                data = [_data(ENTITY_UNKNOWN, client.writer, sn, payload, inline)]
            client.history[sn] = data
            client.waiting[sn] = waiter
            self._trim(client)
            first = self._first(client)
            for guid, entry in client.readers.items():
                beat = self._heartbeat(guid[12:], client.writer, first, sn)
                self._deliver(guid[:12], data, beat, entry.endpoint.addresses)
        try:
            while not waiter.event.wait(POLL):
                if until() or self.closed.is_set():
                    return None
            return waiter.reply
        finally:
            with self.lock:
                client.waiting.pop(sn, None)

    def close(self) -> None:
        """End the thread, close the sockets (an announcement that we left goes first)."""
        if self.closed.is_set():
            return
        self.closed.set()
        self._thread.join(2.0)
        with self.lock:
            guid = self.prefix + PARTICIPANT
            inline = (
                _param(PID_KEY_HASH, guid)
                + _param(PID_STATUS_INFO, b"\x00\x00\x00\x03")
                + struct.pack("<HH", PID_SENTINEL, 0)
            )
            bye = self._header() + _data(SPDP_READER, SPDP_WRITER, 2, b"", inline)
            targets = self._peers() + [a for r in self.remotes.values() for a in r.metatraffic]
            self._send(bye, targets)
        self.unicast.close()
        if self.multicast is not None:
            self.multicast.close()


def _data(reader: bytes, writer: bytes, sn: int, payload: bytes, inline: bytes = b"") -> bytes:
    flags = 1 | (2 if inline else 0) | (4 if payload else 0)
    body = struct.pack("<HH", 0, 16) + reader + writer + _pack_sn(sn) + inline + payload
    if len(body) > 0xFFFF:
        raise ValueError(f"a sample of {len(payload)} bytes does not fit one DATA submessage")
    return struct.pack("<BBH", DATA, flags, len(body)) + body


def _fragments(reader: bytes, writer: bytes, sn: int, payload: bytes, inline: bytes) -> list[bytes]:
    """``payload`` as DATA_FRAG submessages of FRAGMENT bytes, one fragment each, the inline
    QoS in every one (whichever arrives first carries the related sample identity)."""
    out = []
    for number, start in enumerate(range(0, len(payload), FRAGMENT), 1):
        chunk = payload[start : start + FRAGMENT]
        body = (
            struct.pack("<HH", 0, 28)
            + reader
            + writer
            + _pack_sn(sn)
            + struct.pack("<IHHI", number, 1, FRAGMENT, len(payload))
            + inline
            + chunk
        )
        pad = -len(body) % 4
        body += bytes(pad)
        out.append(struct.pack("<BBH", DATA_FRAG, 1 | (2 if inline else 0), len(body)) + body)
    return out


def _gap(reader: bytes, writer: bytes, sn: int) -> bytes:
    body = reader + writer + _pack_sn(sn) + _pack_sn(sn + 1) + struct.pack("<I", 0)
    return struct.pack("<BBH", GAP, 1, len(body)) + body


def _local(addresses: list[tuple[str, int]]) -> list[tuple[str, int]]:
    """Where to send: one locator on this host is enough (as 127.0.0.1); else all of them."""
    if not addresses:
        return []
    mine = _host_addresses()
    for address, port in addresses:
        if address in mine or address.startswith("127."):
            return [("127.0.0.1", port)]
    return addresses


_HOST: list[set[str]] = []


def _host_addresses() -> set[str]:
    if not _HOST:
        _HOST.append(set(_interface_addresses()))
    return _HOST[0]


def _buffers(sock: socket.socket) -> None:
    try:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 20)
    except OSError:
        pass
