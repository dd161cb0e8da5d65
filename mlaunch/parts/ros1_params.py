"""The program that loads a native ROS 1 run's parameter server, as roslaunch loads it.

``python -m mlaunch.parts.ros1_params FILE``: FILE (written by ``mlaunch.parts.ros1_native``)
holds the master's URI, the run id, the namespaces to clear and the parameters. It waits for
the master (one mlaunch starts may still be coming up), sets ``/run_id`` when the master has
none, deletes each ``clear_params`` namespace that exists, then sets every parameter in one
XML-RPC multicall (roslaunch's order and calls), and exits 0; the nodes start after it.
"""

from __future__ import annotations

import pickle
import sys
import time
import xmlrpc.client
from typing import Any

CALLER = "/roslaunch"
WAIT_SECONDS = 30.0


def master_ready(uri: str) -> bool:
    """Whether a ROS 1 master answers at ``uri``."""
    import socket

    proxy: Any = xmlrpc.client.ServerProxy(uri)
    old = socket.getdefaulttimeout()
    socket.setdefaulttimeout(1.0)
    try:
        code, _, _ = proxy.getPid(CALLER)
        return bool(code == 1)
    except (OSError, xmlrpc.client.Error):
        return False
    finally:
        socket.setdefaulttimeout(old)


def xmlrpc_value(value: Any) -> Any:
    """A parameter as XML-RPC carries it (binfile data as Binary)."""
    if isinstance(value, bytes):
        return xmlrpc.client.Binary(value)
    if isinstance(value, dict):
        return {str(k): xmlrpc_value(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [xmlrpc_value(v) for v in value]
    return value


def load(job: dict[str, Any]) -> None:
    uri = job["master_uri"]
    deadline = time.monotonic() + WAIT_SECONDS
    while not master_ready(uri):
        if time.monotonic() > deadline:
            raise SystemExit(f"no ROS master answers at {uri} after {WAIT_SECONDS:.0f} s")
        time.sleep(0.1)  # the master mlaunch started is binding its port
    master: Any = xmlrpc.client.ServerProxy(uri, allow_none=True)
    code, _, found = master.hasParam(CALLER, "/run_id")
    if code == 1 and not found:
        master.setParam(CALLER, "/run_id", job["run_id"])
    for name in job["clear_params"]:
        code, _, found = master.hasParam(CALLER, name)
        if code == 1 and found:
            master.deleteParam(CALLER, name)
    multi: Any = xmlrpc.client.MultiCall(master)
    for key, value in job["params"].items():
        multi.setParam(CALLER, key, xmlrpc_value(value))
    answers: Any = multi()
    for code, message, _ in answers:
        if code != 1:
            raise SystemExit(f"the master refused a parameter: {message}")


def main(argv: list[str]) -> int:
    if len(argv) != 1:
        print("usage: python -m mlaunch.parts.ros1_params JOBFILE", file=sys.stderr)
        return 2
    with open(argv[0], "rb") as f:
        job = pickle.load(f)
    try:
        load(job)
    except (OSError, xmlrpc.client.Error) as e:
        print(f"loading the parameter server failed: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
