"""A process under test for the launch_testing examples: says hello, counts, says goodbye.

--count N lines "count K" every --period seconds, then waits to be stopped (or exits with
--exit CODE when given); "goodbye" on SIGINT/SIGTERM, exit 0. --stderr sends the count to stderr.
"""

import argparse
import signal
import sys
import time

parser = argparse.ArgumentParser()
parser.add_argument("--count", type=int, default=3)
parser.add_argument("--period", type=float, default=0.1)
parser.add_argument("--exit", type=int, default=None)
parser.add_argument("--stderr", action="store_true")
parser.add_argument("words", nargs="*")
args = parser.parse_args()


def goodbye(signum, frame):
    print("goodbye", flush=True)
    sys.exit(0)


signal.signal(signal.SIGINT, goodbye)
signal.signal(signal.SIGTERM, goodbye)
print("hello " + " ".join(args.words), flush=True)
out = sys.stderr if args.stderr else sys.stdout
for k in range(args.count):
    print(f"count {k}", file=out, flush=True)
    time.sleep(args.period)
if args.exit is not None:
    print(f"leaving with {args.exit}", flush=True)
    sys.exit(args.exit)
while True:
    time.sleep(3600)
