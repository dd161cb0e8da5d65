"""Run by Debian's /usr/bin/python3 (ROS 1's rospy), never imported by mlaunch: counts the
messages of one ROS 1 topic for ``mlaunch test`` on a native ROS 1 run.

argv: TOPIC. The master is ``ROS_MASTER_URI``. It subscribes with ``rospy.AnyMsg`` (no message
package needed) and writes one line per message on stdout (``m``); a line ``e WHY`` says why it
cannot. It ends when its stdin closes, so it never outlives the mlaunch that started it.
"""

import os
import sys
import threading


def main() -> None:
    topic = sys.argv[1]
    try:
        import rospy
    except ImportError as e:
        why = f"rospy cannot be imported under {sys.executable} ({e})"
        say(f"e {why}: apt-get install python3-rospy")
        return
    lock = threading.Lock()

    def on_message(_message: object) -> None:
        with lock:
            say("m")

    threading.Thread(target=wait_for_eof, daemon=True).start()
    try:
        rospy.init_node("_mlaunch_test", anonymous=True, disable_signals=True)
        rospy.Subscriber(topic, rospy.AnyMsg, on_message, queue_size=100)
    except Exception as e:  # whatever rospy raised: said, not a traceback
        say(f"e cannot subscribe to {topic}: {e}")
        return
    threading.Event().wait()


def say(line: str) -> None:
    try:
        sys.stdout.write(line + "\n")
        sys.stdout.flush()
    except (BrokenPipeError, ValueError):
        os._exit(0)


def wait_for_eof() -> None:
    """mlaunch holds our stdin open while it watches: its end (closed or mlaunch gone) is ours."""
    while sys.stdin.buffer.read(4096):
        pass
    os._exit(0)


if __name__ == "__main__":
    main()
    sys.stdout.flush()
    os._exit(0)
