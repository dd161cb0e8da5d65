"""Composable nodes loaded for real: the LoadNode driver against rclpy containers.

A recording container (tests/nodes/recording_container.py) prints every request it receives:
the Python, XML and YAML demo files must send exactly the requests of test_composition's
EXPECTED, in order. mlaunch's container stand-in hosts robot_state_publisher's component and
refuses an unknown plugin with its one-line reason, which the driver logs as launch_ros does.
"""

from __future__ import annotations

import importlib.util
import json
import sys
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
from conftest import requires_rclpy
from procutil import wait_until
from test_composition import EXPECTED, HERE, loads, plan_of
from test_composition import prefix as prefix  # the fixture, used by name
from test_standin_nodes import URDF, Proc, spawn, standin

from mlaunch import readers
from mlaunch.launch_ros.composition import LoadComponents
from mlaunch.launch_ros.load_request import (
    BOOL,
    INTEGER,
    STRING,
    STRING_ARRAY,
    LoadRequest,
    TypedParameter,
)

requires_composition_interfaces = pytest.mark.skipif(
    importlib.util.find_spec("composition_interfaces") is None,
    reason="composition_interfaces is not built: run scripts/setup (it builds the interfaces)",
)
pytestmark = [requires_rclpy, requires_composition_interfaces, pytest.mark.timeout(90)]
__all__ = ["spawn"]  # the fixture, used by name

RECORDER = str(Path(__file__).parent / "nodes" / "recording_container.py")


@pytest.fixture
def ros_context(ros_env: dict[str, str]) -> Iterator[Any]:
    """An rclpy context in the test's domain (the tests' probes of the graph)."""
    import rclpy

    context = rclpy.Context()
    rclpy.init(context=context)
    try:
        yield context
    finally:
        context.try_shutdown()


@pytest.fixture(params=["rtps", "rclpy"])
def loader(
    request: pytest.FixtureRequest, ros_env: dict[str, str], ros_context: Any
) -> Iterator[tuple[Any, list[tuple[str, str]]]]:
    """A ComponentLoader in the test's domain, over each link (mlaunch.parts.loadnode_links:
    RTPS of its own, or rclpy on the test's context), and its log lines."""
    from mlaunch.parts.components import ComponentLoader
    from mlaunch.parts.loadnode_links import RclpyLink, RtpsLink
    from mlaunch.parts.rtps import discovery_range

    if request.param == "rtps":
        scope = discovery_range(ros_env)
        assert scope is not None
        link: Any = RtpsLink(int(ros_env["ROS_DOMAIN_ID"]), scope)
    else:
        link = RclpyLink(ros_context)
    lines: list[tuple[str, str]] = []
    driver = ComponentLoader(link, lambda level, message: lines.append((level, message)))
    try:
        yield driver, lines
    finally:
        driver.stop.set()
        driver.join(5.0)
        driver.close()


class _Skip(Exception):
    """The rest of a test does not apply to this link."""


def as_lists(request: LoadRequest) -> dict[str, Any]:
    """A request as the recording container prints it (JSON: tuples are lists)."""
    out = {name: getattr(request, name) for name in request._fields}
    for key in ("parameters", "extra_arguments"):
        out[key] = [[p.name, p.type, p.value] for p in out[key]]
    loaded: dict[str, Any] = json.loads(json.dumps(out))
    return loaded


def recorded(proc: Proc, count: int) -> Callable[[], bool]:
    def check() -> bool:
        if proc.popen.poll() is not None:
            raise AssertionError(f"container exited: {proc.stderr()[-2000:]}")
        return len(proc.stdout().splitlines()) >= count

    return check


def stalled(container: Proc, lines: list[tuple[str, str]]) -> str:
    """Why the loads did not finish: what the container received and said, what the driver said."""
    received = container.stdout().splitlines()
    return (
        f"the loads did not finish within 30 s; the container received {len(received)}"
        f" requests (last: {received[-1:]}), its stderr ends {container.stderr()[-1500:]!r};"
        f" the driver said {lines}"
    )


@pytest.mark.parametrize("suffix", ["py", "xml", "yaml"])
def test_the_recording_container_receives_launch_ros_requests(
    suffix: str, prefix: Path, spawn: Callable[..., Proc], loader: Any
) -> None:
    driver, lines = loader
    container = spawn(
        [
            sys.executable,
            RECORDER,
            "--fail",
            "composition::Server",
            "--ros-args",
            "-r",
            "__node:=my_container",
        ],
        "recorder",
    )
    path = str(HERE / f"demo.launch.{suffix}")
    plan = plan_of(readers.load(path), path, prefix)
    steps = [s for s in plan.steps if isinstance(s, LoadComponents)]
    for step in steps:
        driver.start(step)
        assert driver.join(30.0), stalled(container, lines)
    want = [as_lists(r) for _, requests in EXPECTED for r in requests]
    assert wait_until(recorded(container, len(want)), 10), "the recorded requests"
    got = [json.loads(line) for line in container.stdout().splitlines()]
    assert got == want
    # The container as the file names it (target 'my_container'), as launch_ros logs it.
    assert ("INFO", "Loaded node '/robot/client' in container 'my_container'") in lines
    assert (
        "ERROR",
        "Failed to load node 'server' of type 'composition::Server' in container"
        " 'my_container': refused by the recording container",
    ) in lines
    assert [r.success for r in driver.results] == [True, True, True, False]
    assert len(loads(plan)) == 2


def test_every_step_loads_through_one_node(prefix: Path, loader: Any, ros_context: Any) -> None:
    """Steps waiting for their containers at once are clients of one loader node (a node per
    step cost ~0.35 MB and 1.5 ms each: 27 of them on Autoware's planning_simulator), and a
    stop still abandons each load with its own line. (Over RTPS: one participant, whose
    clients are not a ROS node's.)"""
    from rclpy.node import Node

    driver, lines = loader
    path = str(HERE / "demo.launch.py")
    plan = plan_of(readers.load(path), path, prefix)
    step = next(s for s in plan.steps if isinstance(s, LoadComponents))
    assert isinstance(step, LoadComponents)
    targets = ["/nowhere_a", "/nowhere_b"]
    for target in targets:
        driver.start(LoadComponents(step.origin, target, step.requests[:1], step.written))
    wanted = {f"{target}/_container/load_node" for target in targets}
    probe = Node("loader_probe", context=ros_context)
    clients: dict[str, set[str]] = {}
    try:
        if driver.link.name == "rtps":
            participant = driver.link._made()
            assert wait_until(
                lambda: {c.service for c in list(participant.clients.values())} == wanted, 15
            ), participant.clients
            raise _Skip

        def one_node_has_both() -> bool:
            for name, namespace in probe.get_node_names_and_namespaces():
                if name.startswith("_mlaunch_loader_"):
                    found = probe.get_client_names_and_types_by_node(name, namespace)
                    clients[name] = {service for service, _ in found}
            return any(wanted <= services for services in clients.values())

        assert wait_until(one_node_has_both, 15), clients
        name = next(n for n, services in clients.items() if wanted <= services)
        served = probe.get_service_names_and_types_by_node(name, "/")
        assert not [s for s, _ in served if "type_description" in s], served
    except _Skip:
        pass
    finally:
        probe.destroy_node()
    driver.stop.set()
    assert driver.join(10.0)
    abandoned = [m for level, m in lines if level == "WARNING" and "never loaded" in m]
    assert len(abandoned) == 2, lines


def test_the_standin_container_hosts_robot_state_publisher_and_refuses_unknown_plugins(
    spawn: Callable[..., Proc], loader: Any, ros_context: Any
) -> None:
    driver, lines = loader
    spawn(standin("container", "--ros-args", "-r", "__node:=box"), "container")
    rsp = LoadRequest(
        "robot_state_publisher",
        "robot_state_publisher::RobotStatePublisher",
        parameters=(TypedParameter("robot_description", STRING, URDF),),
    )
    unknown = LoadRequest("composition", "composition::Talker", "talker", "/ns")
    driver.start(LoadComponents("t", "/box", (rsp, unknown)))
    assert driver.join(30.0), "the loads did not finish within 30 s"
    ok, refused = driver.results
    assert (ok.success, ok.full_node_name, ok.unique_id) == (True, "/robot_state_publisher", 1)
    assert not refused.success
    assert refused.error_message.startswith(
        "mlaunch's container stand-in cannot load plugin 'composition::Talker' of package"
        " 'composition'"
    )
    assert ("INFO", "Loaded node '/robot_state_publisher' in container '/box'") in lines
    assert any(
        level == "ERROR" and "'talker' of type 'composition::Talker'" in m for level, m in lines
    )
    names = list_nodes(ros_context, "/box")
    assert names == ["/robot_state_publisher"]


def test_the_standin_container_reads_extra_arguments_as_jazzys_container(
    spawn: Callable[..., Proc], loader: Any, ros_context: Any
) -> None:
    """use_intra_process_comms and forward_global_arguments must be booleans (rclcpp's
    message otherwise), other names are ignored, and forward_global_arguments=true gives the
    component the container's own remaps (here robot_description -> desc_fwd)."""
    driver, lines = loader
    spawn(
        standin(
            "container", "--ros-args", "-r", "__node:=xbox", "-r", "robot_description:=desc_fwd"
        ),
        "container",
    )
    urdf = (TypedParameter("robot_description", STRING, URDF),)
    rsp = "robot_state_publisher::RobotStatePublisher"

    def request(name: str, *extra: TypedParameter) -> LoadRequest:
        return LoadRequest(
            "robot_state_publisher", rsp, name, parameters=urdf, extra_arguments=extra
        )

    driver.start(
        LoadComponents(
            "t",
            "/xbox",
            (
                request("bad", TypedParameter("use_intra_process_comms", STRING, "yes")),
                request("worse", TypedParameter("forward_global_arguments", INTEGER, 1)),
                request(
                    "plain",
                    TypedParameter("use_intra_process_comms", BOOL, True),
                    TypedParameter("not_read_by_rclcpp", INTEGER, 3),
                ),
                request("fwd", TypedParameter("forward_global_arguments", BOOL, True)),
            ),
        )
    )
    assert driver.join(30.0), "the loads did not finish within 30 s"
    bad, worse, plain, fwd = driver.results
    assert (bad.success, bad.error_message) == (
        False,
        "Extra component argument 'use_intra_process_comms' must be a boolean",
    )
    assert (worse.success, worse.error_message) == (
        False,
        "Extra component argument 'forward_global_arguments' must be a boolean",
    )
    assert (
        "ERROR",
        f"Failed to load node 'bad' of type '{rsp}' in container '/xbox': Extra component"
        " argument 'use_intra_process_comms' must be a boolean",
    ) in lines
    assert (plain.success, plain.full_node_name) == (True, "/plain")
    assert (fwd.success, fwd.full_node_name) == (True, "/fwd")
    from rclpy.node import Node

    probe = Node("graph_probe", context=ros_context)
    try:
        topics: dict[str, set[str]] = {"fwd": set(), "plain": set()}

        def published() -> bool:
            for name in topics:
                try:
                    found = probe.get_publisher_names_and_types_by_node(name, "/")
                except Exception:  # not discovered yet
                    continue
                topics[name] = {topic for topic, _ in found}
            return "/desc_fwd" in topics["fwd"] and "/robot_description" in topics["plain"]

        assert wait_until(published, 15), topics
        assert "/desc_fwd" not in topics["plain"]
        assert "/robot_description" not in topics["fwd"]
    finally:
        probe.destroy_node()


def list_nodes(context: Any, container: str) -> list[str]:
    """The container's ListNodes answer (full node names)."""
    from composition_interfaces.srv import ListNodes
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.node import Node

    node = Node("list_probe", context=context)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    try:
        client = node.create_client(ListNodes, f"{container}/_container/list_nodes")
        assert client.wait_for_service(timeout_sec=10.0)
        future = client.call_async(ListNodes.Request())
        executor.spin_until_future_complete(future, timeout_sec=10.0)
        assert future.done()
        return list(future.result().full_node_names)
    finally:
        executor.shutdown()
        node.destroy_node()


@pytest.mark.slow
def test_composed_jtbot_passes_mlaunch_test(ros_env: dict[str, str], tmp_path: Path) -> None:
    """jtbot with the state publisher as a component: the component is a node of the graph
    (expected by default) and publishes the description; a refused plugin would fail it."""
    import subprocess

    from procutil import REPO, clean_env, mlaunch

    env = clean_env(**{k: ros_env[k] for k in ("ROS_DOMAIN_ID", "ROS_AUTOMATIC_DISCOVERY_RANGE")})
    env["ROS_LOG_DIR"] = str(tmp_path / "log")
    done = subprocess.run(
        mlaunch(
            "test",
            str(REPO / "launches" / "jtbot_composed.launch.py"),
            "rviz:=false",
            "--expect-topic",
            "/robot_description",
            "--expect-topic",
            "/joint_states",
        ),
        capture_output=True,
        text=True,
        env=env,
        timeout=120,
    )
    out = done.stdout + done.stderr
    assert done.returncode == 0, done.stdout[-4000:] + done.stderr[-2000:]
    assert "node /robot_state_publisher is in the ROS graph" in out
    assert "Loaded node '/robot_state_publisher' in container '/jtbot_container'" in out


@pytest.mark.parametrize("loader_env", ["", "rclpy"])
def test_a_run_of_composable_nodes_loads_them_without_rclpy(
    ros_env: dict[str, str], tmp_path: Path, loader_env: str
) -> None:
    """The launcher's only ROS need here is LoadNode: over RTPS it imports no rclpy (the run's
    largest cost in memory); MLAUNCH_LOADER=rclpy goes through rclpy as before."""
    import signal
    import subprocess

    from procutil import REPO, clean_env, mlaunch

    env = clean_env(**{k: ros_env[k] for k in ("ROS_DOMAIN_ID", "ROS_AUTOMATIC_DISCOVERY_RANGE")})
    env["ROS_LOG_DIR"] = str(tmp_path / "log")
    if loader_env:
        env["MLAUNCH_LOADER"] = loader_env
    out = tmp_path / "out"
    with open(out, "wb") as sink:
        run = subprocess.Popen(
            mlaunch(str(REPO / "launches" / "jtbot_composed.launch.py"), "rviz:=false"),
            stdout=sink,
            stderr=subprocess.STDOUT,
            stdin=subprocess.DEVNULL,
            env=env,
        )
    try:
        loaded = "Loaded node '/robot_state_publisher' in container '/jtbot_container'"
        assert wait_until(lambda: loaded in out.read_text(), 60), out.read_text()[-3000:]
        maps = Path(f"/proc/{run.pid}/maps").read_text()
        assert ("rclpy" in maps) == (loader_env == "rclpy"), loader_env
    finally:
        run.send_signal(signal.SIGINT)
        assert run.wait(30) == 130, out.read_text()[-3000:]


def test_a_loaded_component_unloads_and_loads_again(
    spawn: Callable[..., Proc], loader: Any, ros_context: Any
) -> None:
    """``mlaunch ctl unload``/``load``'s path: UnloadNode with the container's unique id, then
    the same request again; an unload the container refuses carries its message."""
    import threading

    driver, lines = loader
    spawn(standin("container", "--ros-args", "-r", "__node:=ubox"), "container")
    rsp = LoadRequest(
        "robot_state_publisher",
        "robot_state_publisher::RobotStatePublisher",
        "rsp",
        parameters=(TypedParameter("robot_description", STRING, URDF),),
    )
    driver.start(LoadComponents("t", "/ubox", (rsp,)))
    assert driver.join(30.0)
    (component,) = driver.components
    assert (component.state, component.name, component.unique_id) == ("loaded", "/rsp", 1)
    done = threading.Event()
    driver.unload(component, lambda _: done.set())
    assert done.wait(30.0)
    assert (component.state, component.error) == ("unloaded", "")
    assert ("INFO", "Unloaded node '/rsp' from container '/ubox'") in lines
    assert list_nodes(ros_context, "/ubox") == []
    assert driver.reload(component).join(30.0) is None
    assert (component.state, component.unique_id) == ("loaded", 2)
    component.unique_id = 99  # a node the container does not have: it refuses, and says why
    done.clear()
    driver.unload(component, lambda _: done.set())
    assert done.wait(30.0)
    assert component.state == "loaded"
    assert "99" in component.error, component.error
    assert list_nodes(ros_context, "/ubox") == ["/rsp"]


def test_over_rtps_in_the_subnet_range(
    ros_env: dict[str, str], spawn: Callable[..., Proc], tmp_path: Path
) -> None:
    """ROS 2's default range (SUBNET): discovery by multicast, the domain's own group port;
    the container then answers as on localhost."""
    from mlaunch.parts.components import ComponentLoader
    from mlaunch.parts.loadnode_links import RtpsLink

    ros_env["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "SUBNET"  # the container's environment
    container = spawn(
        [sys.executable, RECORDER, "--fail", "p::Bad", "--ros-args", "-r", "__node:=sbox"], "rec"
    )
    lines: list[tuple[str, str]] = []
    driver = ComponentLoader(
        RtpsLink(int(ros_env["ROS_DOMAIN_ID"]), "SUBNET"), lambda *line: lines.append(line)
    )
    try:
        good = LoadRequest("p", "p::Good", "good", parameters=(TypedParameter("n", INTEGER, 3),))
        driver.start(LoadComponents("t", "/sbox", (good, LoadRequest("p", "p::Bad", "bad"))))
        assert driver.join(30.0), stalled(container, lines)
        assert [(r.success, r.full_node_name) for r in driver.results] == [
            (True, "/good"),
            (False, ""),
        ]
        assert driver.results[1].error_message == "refused by the recording container"
        assert json.loads(container.stdout().splitlines()[0]) == as_lists(good)
    finally:
        driver.stop.set()
        driver.join(5.0)
        driver.close()


def test_a_request_larger_than_a_datagram_arrives_whole(
    spawn: Callable[..., Proc], loader: Any
) -> None:
    """Autoware's planners send requests of ~94 kB (their parameters): over RTPS in fragments
    (DATA_FRAG), which Fast DDS puts together; the container records the request whole."""
    driver, lines = loader
    container = spawn([sys.executable, RECORDER, "--ros-args", "-r", "__node:=big"], "rec")
    values = tuple(f"value {n} " * 20 for n in range(600))  # ~110 kB of strings
    request = LoadRequest(
        "p",
        "p::Big",
        "big_node",
        parameters=(
            TypedParameter("many", STRING_ARRAY, values),
            TypedParameter("after", INTEGER, 7),
        ),
    )
    driver.start(LoadComponents("t", "/big", (request,)))
    assert driver.join(30.0), stalled(container, lines)
    assert [r.success for r in driver.results] == [True]
    assert wait_until(recorded(container, 1), 10)
    assert json.loads(container.stdout().splitlines()[0]) == as_lists(request)


def test_a_flood_of_garbage_on_the_rtps_port_does_not_stall_a_load(
    ros_env: dict[str, str], spawn: Callable[..., Proc]
) -> None:
    """Datagrams of noise and truncated RTPS sent to the launcher's discovery port as fast as
    a thread can while it discovers the container and loads: the load completes."""
    import os
    import socket
    import threading

    from mlaunch.parts.components import ComponentLoader
    from mlaunch.parts.loadnode_links import RtpsLink

    link = RtpsLink(int(ros_env["ROS_DOMAIN_ID"]), "LOCALHOST")
    lines: list[tuple[str, str]] = []
    driver = ComponentLoader(link, lambda *line: lines.append(line))
    link.prepare()
    port = link._made().port
    done = threading.Event()
    sent = [0]

    def flood() -> None:
        sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        noise = [os.urandom(n) for n in (0, 7, 20, 300, 1400)]
        noise += [b"RTPS\x02\x03\x01\x0f" + os.urandom(12) + os.urandom(n) for n in (4, 40, 900)]
        while not done.is_set():
            for data in noise:
                try:
                    sock.sendto(data, ("127.0.0.1", port))
                    sent[0] += 1
                except OSError:
                    pass
        sock.close()

    flooder = threading.Thread(target=flood, daemon=True)
    flooder.start()
    try:
        container = spawn([sys.executable, RECORDER, "--ros-args", "-r", "__node:=fbox"], "rec")
        driver.start(LoadComponents("t", "/fbox", (LoadRequest("p", "p::A", "a"),)))
        assert driver.join(60.0), stalled(container, lines)
        assert [r.success for r in driver.results] == [True]
    finally:
        done.set()
        flooder.join(5.0)
        driver.stop.set()
        driver.join(5.0)
        driver.close()
    assert sent[0] > 1000
