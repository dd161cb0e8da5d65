"""What `mlaunch test`'s recorder costs: CPU time per MB/s recorded, and the MCAP write.

    .venv/bin/python benchmarks/recorder_cpu.py [--rate-mb 2,8] [--seconds 10] [--ros-domain ID]

For each rate, a publisher process (rclpy) sends std_msgs/String messages of 64 KiB (random text) at the rate
that makes that many MB/s; this process runs mlaunch.smoke.recorder.Recorder on the topic through a
RosGraph, as `mlaunch test` does (its raw subscription and ring buffer, 10 s kept), for ``--seconds`` and measures its own CPU time (user +
system, this process does nothing else meanwhile) against the bytes received. Then it writes the
ring as MCAP and measures that. It prints one line per rate and the cost in % of one core per
MB/s. A measurement, not a test: run it on an idle machine for figures to compare.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))

PUBLISHER = """
import base64, os, sys, time
import rclpy
from rclpy.node import Node
from std_msgs.msg import String

rate_mb, size = float(sys.argv[1]), int(sys.argv[2])
hz = rate_mb * 1e6 / size
rclpy.init()
node = Node("bench_publisher")
pub = node.create_publisher(String, "/bench", 10)
# Random text, new each time: the MCAP's compression must not make the figures look small.
node.create_timer(
    1.0 / hz,
    lambda: pub.publish(String(data=base64.b64encode(os.urandom(size * 3 // 4)).decode())),
)
try:
    rclpy.spin(node)
except BaseException:
    pass
"""
SIZE = 64 * 1024


def measure(rate_mb: float, seconds: float, environ: dict[str, str]) -> dict[str, float]:
    from mlaunch.parts.bridge import RosGraph
    from mlaunch.smoke.recorder import Recorder

    publisher = subprocess.Popen(
        [sys.executable, "-c", PUBLISHER, str(rate_mb), str(SIZE)], env=environ
    )
    try:
        graph = RosGraph(node_name="_bench_recorder", environ=environ)
        graph.start()
        recorder = Recorder(["/bench"], 10.0)
        recorder.attach(graph)
        deadline = time.monotonic() + 30
        while recorder.received == 0 and time.monotonic() < deadline:
            time.sleep(0.1)
        got0, cpu0, wall0 = recorder.received, time.process_time(), time.monotonic()
        time.sleep(seconds)
        got1, cpu1, wall1 = recorder.received, time.process_time(), time.monotonic()
        graph.close()
        with tempfile.TemporaryDirectory() as folder:
            start = time.process_time()
            count, _ = recorder.write(os.path.join(folder, "r.mcap"))
            write_cpu = time.process_time() - start
            size = os.path.getsize(os.path.join(folder, "r.mcap"))
    finally:
        publisher.terminate()
        publisher.wait(10)
    mb_s = (got1 - got0) * SIZE / 1e6 / (wall1 - wall0)
    cpu_share = (cpu1 - cpu0) / (wall1 - wall0)
    return {
        "asked_mb_s": rate_mb,
        "mb_s": mb_s,
        "cpu_percent": 100 * cpu_share,
        "cpu_percent_per_mb_s": 100 * cpu_share / mb_s if mb_s else float("nan"),
        "write_messages": count,
        "write_cpu_s": write_cpu,
        "mcap_mb": size / 1e6,
    }


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--rate-mb", default="2,8", help="MB/s to publish, comma-separated")
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--ros-domain", type=int, default=None)
    args = parser.parse_args()
    environ = dict(os.environ)
    environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    from ros_domain import private_domain

    with private_domain() as domain:
        environ["ROS_DOMAIN_ID"] = str(args.ros_domain if args.ros_domain is not None else domain)
        for rate in (float(r) for r in args.rate_mb.split(",")):
            r = measure(rate, args.seconds, environ)
            print(
                f"{r['mb_s']:6.2f} MB/s recorded: {r['cpu_percent']:5.1f} % of a core"
                f" ({r['cpu_percent_per_mb_s']:.1f} % per MB/s); MCAP of the last 10 s:"
                f" {r['write_messages']} messages, {r['mcap_mb']:.1f} MB in"
                f" {r['write_cpu_s']:.2f} s CPU",
                flush=True,
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
