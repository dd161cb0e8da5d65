"""The RTPS LoadNode client's pieces: its CDR, its parsing of what arrives, when it is used.

The interop with real containers (rclpy's and the C++ one) is in test_composition_ros.py and
test_real_nodes.py; here: the bytes of LoadNode and UnloadNode (against rclpy's own
serialization where rclpy is built), garbage and truncated input dropped without an exception,
and the environments where rclpy must be used instead.
"""

from __future__ import annotations

import importlib.util
import random
import struct
import threading
from collections.abc import Iterator
from typing import Any

import pytest

from mlaunch.launch_ros.load_request import (
    BOOL,
    BOOL_ARRAY,
    BYTE_ARRAY,
    DOUBLE,
    DOUBLE_ARRAY,
    INTEGER,
    INTEGER_ARRAY,
    NOT_SET,
    STRING,
    STRING_ARRAY,
    LoadRequest,
    TypedParameter,
)
from mlaunch.parts import loadnode_cdr as cdr
from mlaunch.parts import rtps

requires_interfaces = pytest.mark.skipif(
    importlib.util.find_spec("composition_interfaces") is None
    or importlib.util.find_spec("rclpy") is None,
    reason="rclpy and composition_interfaces are not built: run scripts/setup",
)

EVERY_TYPE = LoadRequest(
    "pkg",
    "pkg::Plugin",
    "näme",
    "/ns",
    0,
    ("a:=b", "/x:=/y/z"),
    (
        TypedParameter("unset", NOT_SET, None),
        TypedParameter("flag", BOOL, True),
        TypedParameter("count", INTEGER, -(1 << 63)),
        TypedParameter("rate", DOUBLE, 2.5),
        TypedParameter("text", STRING, "héllo"),
        TypedParameter("bytes", BYTE_ARRAY, (b"\x00", b"\xff")),
        TypedParameter("flags", BOOL_ARRAY, (True, False, True)),
        TypedParameter("counts", INTEGER_ARRAY, (1, -2, (1 << 63) - 1)),
        TypedParameter("rates", DOUBLE_ARRAY, (0.5, -1e300)),
        TypedParameter("texts", STRING_ARRAY, ("", "b", "ccc")),
        TypedParameter("empty", STRING_ARRAY, ()),
    ),
    (TypedParameter("use_intra_process_comms", BOOL, True),),
)


# --- CDR ----------------------------------------------------------------------------------


@requires_interfaces
@pytest.mark.parametrize(
    "request_",
    [EVERY_TYPE, LoadRequest("p", "p::Q"), LoadRequest("p", "p::Q", log_level=40)],
    ids=["every-type", "bare", "log-level"],
)
def test_a_load_request_is_what_rclpy_reads_back(request_: LoadRequest) -> None:
    from composition_interfaces.srv import LoadNode
    from rclpy.serialization import deserialize_message

    from mlaunch.launch_ros.load_request import to_message

    data = cdr.load_request(request_)
    assert data[:4] == b"\x00\x01\x00" + bytes((data[3],)) and len(data) % 4 == 0
    assert deserialize_message(data, LoadNode.Request) == to_message(request_)


@requires_interfaces
def test_rclpys_answers_are_read() -> None:
    from composition_interfaces.srv import LoadNode, UnloadNode
    from rclpy.serialization import serialize_message

    answer = LoadNode.Response(
        success=True, error_message="", full_node_name="/ns/näme", unique_id=(1 << 64) - 1
    )
    got = cdr.load_response(serialize_message(answer))
    assert got == cdr.Response(True, "", "/ns/näme", (1 << 64) - 1)
    refused = UnloadNode.Response(success=False, error_message="No node found with unique_id: 3")
    assert cdr.unload_response(serialize_message(refused)) == cdr.Response(
        False, "No node found with unique_id: 3"
    )


def test_unload_request_bytes() -> None:
    assert cdr.unload_request(9) == b"\x00\x01\x00\x00" + (9).to_bytes(8, "little")


def test_the_body_is_aligned_from_its_start() -> None:
    """XCDR1: a string's length on 4, an int64 on 8, counted after the encapsulation."""
    data = cdr.load_request(LoadRequest("a", "b", parameters=(TypedParameter("n", INTEGER, 7),)))
    body = data[4:]
    # "a", "b", "", "" (4 strings), log level, no remaps, one parameter named "n"
    assert body[:8] == b"\x02\x00\x00\x00a\x00\x00\x00"
    at = body.index(b"n\x00") + 2  # the parameter's name ends; its type, its bool
    assert body[at : at + 2] == bytes((INTEGER, 0))
    integer = at + 2 + (-(at + 2) % 8)
    assert struct.unpack_from("<q", body, integer)[0] == 7


@pytest.mark.parametrize(
    ("parameter", "said"),
    [
        (
            TypedParameter("big", INTEGER, 1 << 63),
            "parameter 'big': 9223372036854775808 is outside",
        ),
        (TypedParameter("f", DOUBLE, "x"), "parameter 'f': 'x' is not a number"),
        (TypedParameter("b", BYTE_ARRAY, (300,)), "parameter 'b': 300 is not a byte"),
        (TypedParameter("s", STRING_ARRAY, ("a", 1)), "is not a list of strings"),
        (TypedParameter("t", STRING, "\udcff"), "is not text"),
    ],
)
def test_a_value_the_message_cannot_carry_is_a_clear_error(
    parameter: TypedParameter, said: str
) -> None:
    with pytest.raises(ValueError, match=said.replace("(", r"\(")):
        cdr.load_request(LoadRequest("p", "p::Q", parameters=(parameter,)))


@pytest.mark.parametrize(
    "data",
    [
        b"",
        b"\x00\x01\x00\x00",  # no body
        b"\x00\x01\x00\x00\x01\x00\x00\x00\xff\xff\xff\x7f",  # a string past the end
        b"\x00\x07\x00\x00" + bytes(32),  # not CDR
        b"\x00\x01\x00\x00\x01\x00\x00\x00\x02\x00\x00\x00\xff\x00",  # not UTF-8
        b"\x00\x01\x00\x00" + bytes(cdr.MAX_REPLY),  # too large to be an answer
    ],
    ids=["empty", "no-body", "past-end", "not-cdr", "not-utf8", "huge"],
)
def test_a_bad_answer_is_a_cdr_error(data: bytes) -> None:
    with pytest.raises(cdr.CdrError):
        cdr.load_response(data)


def test_an_answer_in_big_endian_is_read() -> None:
    body = b"\x01" + b"\x00" * 3 + b"\x00\x00\x00\x03ok\x00" + b"\x00" + b"\x00\x00\x00\x01\x00"
    body += bytes(-len(body) % 8) + (5).to_bytes(8, "big")
    assert cdr.load_response(b"\x00\x00\x00\x00" + body) == cdr.Response(True, "ok", "", 5)


# --- when it is used ----------------------------------------------------------------------

FAST = {"RMW_IMPLEMENTATION": "rmw_fastrtps_cpp", "ROS_DOMAIN_ID": "5"}


@pytest.mark.parametrize(
    ("launcher", "process", "why"),
    [
        ({}, {}, ""),
        (FAST, FAST, ""),
        ({**FAST, "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}, None, ""),
        ({"MLAUNCH_LOADER": "rclpy"}, {}, "MLAUNCH_LOADER=rclpy"),
        ({"MLAUNCH_LOADER": "dds"}, {}, "is not 'rtps' or 'rclpy'"),
        ({}, {"RMW_IMPLEMENTATION": "rmw_cyclonedds_cpp"}, "RMW_IMPLEMENTATION=rmw_cyclonedds"),
        ({"RMW_IMPLEMENTATION": "rmw_zenoh_cpp"}, {}, "RMW_IMPLEMENTATION=rmw_zenoh_cpp"),
        ({}, {"FASTDDS_DEFAULT_PROFILES_FILE": "/p.xml"}, "FASTDDS_DEFAULT_PROFILES_FILE"),
        ({"ROS_DISCOVERY_SERVER": "127.0.0.1:11811"}, {}, "ROS_DISCOVERY_SERVER"),
        ({"ROS_STATIC_PEERS": "10.0.0.2"}, {}, "ROS_STATIC_PEERS"),
        ({}, {"ROS_SECURITY_ENABLE": "true"}, "ROS_SECURITY_ENABLE"),
        ({"ROS_AUTOMATIC_DISCOVERY_RANGE": "OFF"}, {}, "ROS_AUTOMATIC_DISCOVERY_RANGE='OFF'"),
        ({"ROS_AUTOMATIC_DISCOVERY_RANGE": "lan"}, {}, "ROS_AUTOMATIC_DISCOVERY_RANGE='lan'"),
        ({}, {"ROS_DOMAIN_ID": "7"}, "another ROS_DOMAIN_ID"),
        ({}, {"ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}, "another range"),
    ],
)
def test_rtps_stands_in_for_rclpy_only_at_fast_dds_defaults(
    launcher: dict[str, str], process: dict[str, str] | None, why: str
) -> None:
    processes = [] if process is None else [{**launcher, **process}]
    said = rtps.unusable(launcher, processes)
    assert (said == "") == (why == ""), said
    assert why in said


@pytest.mark.parametrize(
    ("environ", "scope"),
    [
        ({}, "SUBNET"),
        ({"ROS_AUTOMATIC_DISCOVERY_RANGE": "SYSTEM_DEFAULT"}, "SUBNET"),
        ({"ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}, "LOCALHOST"),
        # the deprecated variable wins over the range, as rcl (Jazzy) has it
        ({"ROS_LOCALHOST_ONLY": "1", "ROS_AUTOMATIC_DISCOVERY_RANGE": "SUBNET"}, "LOCALHOST"),
        ({"ROS_AUTOMATIC_DISCOVERY_RANGE": "OFF"}, None),
    ],
)
def test_the_discovery_range_is_rcls(environ: dict[str, str], scope: str | None) -> None:
    assert rtps.discovery_range(environ) == scope


def test_the_driver_takes_rtps_without_importing_rclpy() -> None:
    from mlaunch.parts.components import _describe, make_link
    from mlaunch.parts.loadnode_links import RtpsLink

    link = make_link({"ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}, [], 0)
    assert isinstance(link, RtpsLink) and link.scope == "LOCALHOST"
    assert _describe(link) == "LoadNode requests go over RTPS (domain 0, discovery LOCALHOST)"


@requires_interfaces
def test_the_driver_takes_rclpy_when_told() -> None:
    from mlaunch.parts.components import _describe, make_link
    from mlaunch.parts.loadnode_links import RclpyLink

    link = make_link({"MLAUNCH_LOADER": "rclpy"}, [], 0)
    try:
        assert isinstance(link, RclpyLink)
        assert _describe(link) == "LoadNode requests go through rclpy (MLAUNCH_LOADER=rclpy)"
    finally:
        link.close()


# --- what arrives -------------------------------------------------------------------------


@pytest.fixture
def participant(ros_env: dict[str, str]) -> Iterator[rtps.Participant]:
    """A participant in the test's own domain (its ports are the domain's)."""
    made = rtps.Participant(int(ros_env["ROS_DOMAIN_ID"]), "LOCALHOST")
    try:
        yield made
    finally:
        made.close()


def _other(prefix: bytes, participant: rtps.Participant) -> Any:
    """A participant that only makes messages (no sockets, no thread), said to listen where
    ``participant`` does (what it is sent goes nowhere else)."""
    sender = object.__new__(rtps.Participant)
    sender.prefix = prefix
    sender.domain = participant.domain
    sender.port = participant.port
    sender.addresses = ["127.0.0.1"]
    sender.name = "fuzz"
    sender.announced = {rtps.PUB_WRITER: [], rtps.SUB_WRITER: []}
    sender.count = 0
    return sender


# LoadNode.Response(success=True, error_message="", full_node_name="/x", unique_id=0)
REPLY = b"\x01\x00\x00\x00" + b"\x01\x00\x00\x00\x00\x00\x00\x00" + b"\x03\x00\x00\x00/x\x00"
REPLY += bytes(-len(REPLY) % 8) + bytes(8)


def _valid_messages(participant: rtps.Participant) -> list[bytes]:
    """A container's side of a load, as datagrams (its SPDP, its two endpoints, a reply)."""
    prefix = b"\x01\x0f" + bytes(range(10))
    sender = _other(prefix, participant)
    service = "/box/_container/load_node"
    spdp = rtps.Participant._spdp(sender)
    client = rtps.Client(service, "LoadNode", 1, prefix)
    # the container's reader of requests and writer of replies, as it announces them
    request_reader, reply_writer = b"\x00\x00\x02\x04", b"\x00\x00\x03\x03"
    rtps.Participant.endpoint(
        sender, request_reader, rtps.request_topic(service), client.request_type, False
    )
    rtps.Participant.endpoint(
        sender, reply_writer, rtps.reply_topic(service), client.reply_type, True
    )
    head = rtps.Participant._header(sender, participant.prefix)
    sedp = [head + data for _, data in sender.announced[rtps.PUB_WRITER]]
    sedp += [head + data for _, data in sender.announced[rtps.SUB_WRITER]]
    related = rtps._param(
        rtps.PID_RELATED_SAMPLE_IDENTITY,
        participant.prefix + b"\x00\x00\x01\x04" + rtps._pack_sn(1),
    ) + struct.pack("<HH", rtps.PID_SENTINEL, 0)
    reply = head + rtps._data(
        b"\x00\x00\x01\x04",
        reply_writer,
        1,
        cdr.payload(REPLY),
        related,
    )
    beat = head + rtps.Participant._heartbeat(sender, rtps.PUB_READER, rtps.PUB_WRITER, 1, 9)
    gap = head + rtps._gap(rtps.PUB_READER, rtps.PUB_WRITER, 3)
    frags = [head + f for f in rtps._fragments(b"\0\0\0\0", b"\0\0\0\x03", 1, bytes(40000), b"")]
    return [spdp, *sedp, reply, beat, gap, *frags]


def test_garbage_and_mangled_datagrams_are_dropped_without_an_exception(
    participant: rtps.Participant,
) -> None:
    valid = _valid_messages(participant)
    for sample in valid:
        assert participant.receive(sample) in (True, False)
    chance = random.Random(37)
    for _ in range(4000):
        message = bytearray(chance.choice(valid))
        how = chance.randrange(4)
        if how == 0:  # truncated anywhere
            del message[chance.randrange(len(message)) :]
        elif how == 1:  # bytes flipped
            for _ in range(chance.randrange(1, 8)):
                message[chance.randrange(len(message))] = chance.randrange(256)
        elif how == 2:  # a submessage length or a parameter length made huge
            at = chance.randrange(20, max(21, len(message) - 2))
            message[at : at + 2] = b"\xff\xff"
        else:  # noise behind a valid header
            message = message[:20] + bytearray(chance.randbytes(chance.randrange(200)))
        participant.receive(bytes(message))  # must not raise
    for noise in (b"", b"RTPS", b"RTPS\x02\x03" + bytes(14), chance.randbytes(65507)):
        assert participant.receive(noise) in (True, False)
    assert len(participant.remotes) <= rtps.MAX_PARTICIPANTS
    assert participant.error == ""  # each was dropped where the parser expects bad input


def test_a_reply_for_another_client_or_an_unknown_request_is_ignored(
    participant: rtps.Participant,
) -> None:
    """Only the answer naming this client's reply reader and a waiting request is taken."""
    client = participant.client("/box/_container/load_node", "LoadNode")
    valid = _valid_messages(participant)
    for message in valid[:3]:  # the container's participant and endpoints
        participant.receive(message)
    assert client.writers and client.readers
    waiter = rtps.Waiter()
    client.waiting[1] = waiter
    # a reply to sequence number 1 of another client (another reader's GUID)
    other = bytearray(valid[3])
    at = other.index(participant.prefix + b"\x00\x00\x01\x04")
    other[at + 12 : at + 16] = b"\x00\x00\x09\x04"
    other[52:60] = rtps._pack_sn(2)  # its own sample of the container's writer
    assert participant.receive(bytes(other))
    assert waiter.reply is None
    assert participant.receive(valid[3])
    assert waiter.event.is_set() and waiter.reply is not None
    assert cdr.load_response(waiter.reply) == cdr.Response(True, "", "/x", 0)


def test_a_participant_that_says_it_left_is_forgotten(participant: rtps.Participant) -> None:
    client = participant.client("/box/_container/load_node", "LoadNode")
    valid = _valid_messages(participant)
    for message in valid[:3]:
        participant.receive(message)
    assert client.readers
    prefix = valid[0][8:20]
    inline = rtps._param(rtps.PID_KEY_HASH, prefix + rtps.PARTICIPANT) + rtps._param(
        rtps.PID_STATUS_INFO, b"\x00\x00\x00\x03"
    )
    inline += struct.pack("<HH", rtps.PID_SENTINEL, 0)
    bye = valid[0][:20] + rtps._data(rtps.SPDP_READER, rtps.SPDP_WRITER, 2, b"", inline)
    assert participant.receive(bye)
    assert prefix not in participant.remotes
    assert not client.readers and not client.writers
    assert not participant.ready(client)


def test_close_ends_the_thread_and_the_sockets(ros_env: dict[str, str]) -> None:
    before = set(threading.enumerate())
    made = rtps.Participant(int(ros_env["ROS_DOMAIN_ID"]), "SUBNET")
    assert [t.name for t in set(threading.enumerate()) - before] == ["rtps"]
    made.close()
    assert not made._thread.is_alive()
    assert made.unicast.fileno() == -1
    assert made.multicast is not None and made.multicast.fileno() == -1
    made.close()  # twice is no error


# --- a container that never answers, one that leaves ----------------------------------------


def _mute_container(domain: int, target: str) -> rtps.Participant:
    """A participant that serves ``target``'s load_node as far as discovery goes (its request
    reader and reply writer, announced and acknowledging) and never answers a request."""
    container = rtps.Participant(domain, "LOCALHOST", "mute")
    service = f"{target}/_container/load_node"
    kind = rtps.Client(service, "LoadNode", 1, container.prefix)
    with container.lock:
        container.endpoint(
            b"\x00\x00\x07\x04", rtps.request_topic(service), kind.request_type, False
        )
        container.endpoint(b"\x00\x00\x08\x03", rtps.reply_topic(service), kind.reply_type, True)
    return container


def test_a_container_that_never_answers_is_abandoned_at_shutdown(
    ros_env: dict[str, str],
) -> None:
    from procutil import wait_until

    from mlaunch.launch_ros.composition import LoadComponents
    from mlaunch.parts.components import ComponentLoader
    from mlaunch.parts.loadnode_links import RtpsLink

    domain = int(ros_env["ROS_DOMAIN_ID"])
    before = set(threading.enumerate())
    mute = _mute_container(domain, "/mute")
    lines: list[tuple[str, str]] = []
    link = RtpsLink(domain, "LOCALHOST")
    driver = ComponentLoader(link, lambda *line: lines.append(line))
    try:
        driver.start(LoadComponents("t", "/mute", (LoadRequest("p", "p::A", "a"),)))
        participant = link._made()
        client = participant.clients["LoadNode /mute/_container/load_node"]
        # the request went out: the client waits for the answer
        assert wait_until(lambda: client.sn == 1 and bool(client.waiting), 20), lines
        assert not driver.join(0.5)
        driver.stop.set()
        assert driver.join(5.0)
    finally:
        driver.close()
        mute.close()
    assert lines == [
        (
            "WARNING",
            "Abandoning wait for the '/mute/_container/load_node' service response, due to"
            " shutdown: node 'a' of type 'p::A' may not have been loaded",
        )
    ]
    assert not [t for t in set(threading.enumerate()) - before if t.is_alive()]


def test_a_container_that_leaves_is_no_longer_ready(ros_env: dict[str, str]) -> None:
    from procutil import wait_until

    domain = int(ros_env["ROS_DOMAIN_ID"])
    mute = _mute_container(domain, "/gone")
    participant = rtps.Participant(domain, "LOCALHOST")
    try:
        client = participant.client("/gone/_container/load_node", "LoadNode")
        assert wait_until(lambda: participant.ready(client), 20)
        mute.close()  # says it leaves
        assert wait_until(lambda: not participant.ready(client), 10)
        assert mute.prefix not in participant.remotes
    finally:
        participant.close()
        mute.close()


def test_many_announcements_go_in_datagrams_that_fit(participant: rtps.Participant) -> None:
    """A launch with hundreds of containers: its endpoint announcements to a participant are
    split over datagrams UDP carries (one datagram of them all was refused: EMSGSIZE)."""
    for n in range(300):
        participant.client(f"/container_{n}/_container/load_node", "LoadNode")
    sent: list[bytes] = []
    participant._send = lambda data, addresses: sent.append(data)  # type: ignore[method-assign]
    remote = rtps.Remote(b"\x01\x0f" + bytes(10))
    remote.builtin = rtps.BUILTIN_ENDPOINTS
    remote.metatraffic = [("127.0.0.1", 9)]
    with participant.lock:
        participant._offer(remote)
    assert len(sent) > 1 and all(len(d) <= rtps.MAX_DATAGRAM for d in sent)
    topics = {f"rq/container_{n}/_container/load_nodeRequest" for n in range(300)}
    topics |= {f"rr/container_{n}/_container/load_nodeReply" for n in range(300)}
    joined = b"".join(sent)
    assert all(topic.encode() in joined for topic in topics)


def test_an_announcement_in_fragments_is_not_asked_for_again(
    participant: rtps.Participant,
) -> None:
    """A node's endpoint announcement past one datagram (DATA_FRAG) is no container's: noted as
    received, so this reader's ACKNACK does not ask the writer for it forever."""
    valid = _valid_messages(participant)
    participant.receive(valid[0])  # the participant
    prefix = valid[0][8:20]
    head = valid[0][:20]
    frags = rtps._fragments(rtps.PUB_READER, rtps.PUB_WRITER, 1, bytes(40000), b"")
    assert participant.receive(head + frags[0])
    state = participant.states[prefix + rtps.PUB_WRITER]
    assert state.base == 2 and not state.missing(1)
