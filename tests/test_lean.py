"""The launcher's lean rclpy side (mlaunch.parts.lean): its participant's transports are UDPv4
only unless the user configures Fast DDS, only while it is made; malloc arenas are limited."""

from __future__ import annotations

import threading

import pytest

from mlaunch.parts import lean


@pytest.mark.parametrize(
    ("environ", "lean_ok"),
    [
        ({}, True),
        ({"RMW_IMPLEMENTATION": "rmw_fastrtps_cpp"}, True),
        ({"RMW_IMPLEMENTATION": "rmw_cyclonedds_cpp"}, False),
        ({"FASTRTPS_DEFAULT_PROFILES_FILE": "/etc/my.xml"}, False),
        ({"FASTDDS_DEFAULT_PROFILES_FILE": "/etc/my.xml"}, False),
        ({"FASTDDS_BUILTIN_TRANSPORTS": "SHM"}, False),
        ({"RMW_FASTRTPS_USE_QOS_FROM_XML": "1"}, False),
        ({"ROS_DISCOVERY_SERVER": "127.0.0.1:11811"}, False),
        ({"FASTRTPS_DEFAULT_PROFILES_FILE": ""}, True),
    ],
)
def test_the_participant_is_lean_unless_the_user_configures_fast_dds(
    environ: dict[str, str], lean_ok: bool
) -> None:
    assert lean.lean_transports(environ) is lean_ok


def test_the_transport_setting_lasts_only_while_the_participant_is_made() -> None:
    environ: dict[str, str] = {"PATH": "/usr/bin"}
    with lean.lean_participant(environ):
        assert environ == {"PATH": "/usr/bin", "FASTDDS_BUILTIN_TRANSPORTS": "UDPv4"}
    assert environ == {"PATH": "/usr/bin"}
    with pytest.raises(RuntimeError), lean.lean_participant(environ):
        raise RuntimeError("making the node failed")
    assert environ == {"PATH": "/usr/bin"}


def test_a_users_transport_setting_is_left_as_it_is() -> None:
    environ = {"FASTDDS_BUILTIN_TRANSPORTS": "LARGE_DATA"}
    with lean.lean_participant(environ):
        assert environ == {"FASTDDS_BUILTIN_TRANSPORTS": "LARGE_DATA"}
    assert environ == {"FASTDDS_BUILTIN_TRANSPORTS": "LARGE_DATA"}


def test_arenas_are_limited_through_mallopt() -> None:
    calls: list[tuple[int, int]] = []

    def mallopt(param: int, value: int) -> int:
        calls.append((param, value))
        return 1

    assert lean.limit_arenas(mallopt)
    assert calls == [(-8, 2)]  # M_ARENA_MAX in glibc's malloc.h


def test_off_the_main_thread_nothing_is_set() -> None:
    """A LaunchService on a thread of its own (launch_testing): the test's thread may spawn
    with os.environ meanwhile, so the participant keeps the default transports."""
    environ: dict[str, str] = {}
    seen: list[dict[str, str]] = []

    def make() -> None:
        with lean.lean_participant(environ):
            seen.append(dict(environ))

    thread = threading.Thread(target=make)
    thread.start()
    thread.join(10)
    assert seen == [{}]
