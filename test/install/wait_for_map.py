#!/usr/bin/env python3
"""Waits (wall-clock) for a nav_msgs/OccupancyGrid on TOPIC that holds occupied and free cells.
usage: wait_for_map.py TOPIC TIMEOUT_S    exit 0 when one arrives, 1 after the timeout."""
import sys
import threading
import time

import rospy
from nav_msgs.msg import OccupancyGrid


def main():
    topic, timeout = sys.argv[1], float(sys.argv[2])
    done = threading.Event()
    last = {}

    def on_map(msg):
        occupied = sum(1 for v in msg.data if v > 65)
        free = sum(1 for v in msg.data if 0 <= v < 20)
        last.update(width=msg.info.width, height=msg.info.height, frame=msg.header.frame_id,
                    occupied=occupied, free=free)
        if occupied > 0 and free > 0:
            done.set()

    rospy.init_node("wait_for_map", anonymous=True, disable_signals=True)
    rospy.Subscriber(topic, OccupancyGrid, on_map)
    start = time.monotonic()
    ok = done.wait(timeout)
    print("wait_for_map: %s after %.1f s: %s" % (topic, time.monotonic() - start,
                                                 last or "no message"))
    rospy.signal_shutdown("done")
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
