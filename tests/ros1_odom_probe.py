"""Run by /usr/bin/python3 (Debian's rospy and tf): the car's odometry and its TF, as JSON lines.

Every /odom message it takes (at most two a second) is printed with the transform odom ->
base_link that TF holds at that message's stamp: {"odom": [x, y, yaw], "tf": [x, y, yaw]}
("tf": null when TF has none). It ends when its stdin closes. It must not import mlaunch.
"""

import json
import math
import sys
import threading
import time


def yaw(q):
    return math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))


def main():
    import rospy
    import tf
    from nav_msgs.msg import Odometry

    rospy.init_node("odom_probe", anonymous=True, disable_signals=True)
    listener = tf.TransformListener()
    threading.Thread(
        target=lambda: (sys.stdin.read(), rospy.signal_shutdown("eof")), daemon=True
    ).start()
    while not rospy.is_shutdown():
        try:
            msg = rospy.wait_for_message("/odom", Odometry, timeout=5)
        except rospy.ROSException:
            continue
        pose = msg.pose.pose
        out: dict = {"odom": [pose.position.x, pose.position.y, yaw(pose.orientation)], "tf": None}
        try:
            listener.waitForTransform("odom", "base_link", msg.header.stamp, rospy.Duration(2))
            (x, y, _), q = listener.lookupTransform("odom", "base_link", msg.header.stamp)
            out["tf"] = [
                x,
                y,
                math.atan2(2 * (q[3] * q[2] + q[0] * q[1]), 1 - 2 * (q[1] ** 2 + q[2] ** 2)),
            ]
        except tf.Exception as e:
            out["error"] = str(e)
        print(json.dumps(out), flush=True)
        time.sleep(0.5)


if __name__ == "__main__":
    main()
