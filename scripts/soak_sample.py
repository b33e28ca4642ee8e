#!/usr/bin/env python3
"""Sampler of make soak (scripts/soak.sh): every simulated minute, the node's resident memory
(/proc/<pid>/status VmRSS) and the map's bytes (~status), with the scans received and integrated.
When the bag has played (OUT/played appears), advances /clock and resends the bag's last /tf for
a few simulated seconds (as a live localisation would go on doing), so that the scans waiting for
tf beyond the last beam are placed and the node publishes a last ~status, then writes OUT/soak.csv, OUT/soak.png (matplotlib) and
OUT/soak.txt: the slope per hour of both curves (least squares, after the first minute) and the
scans lost (LaserScans in the bag minus scans integrated; must be 0). Exit status 1 if any."""
import argparse
import os
import sys
import threading
import time

import rosbag
import rospy
from rosgraph_msgs.msg import Clock
from wavog_mapping.msg import MapperStatus


def rss_bytes(pid):
    with open("/proc/%d/status" % pid) as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) * 1024
    return 0


def dropped_of(status):
    """Every dropped_* counter of an InputStatus, whatever reasons the message has today."""
    return sum(getattr(status, f) for f in status.__slots__ if f.startswith("dropped_"))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--pid", type=int, required=True)
    ap.add_argument("--bag", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--rate", type=float, default=1.0)
    a = ap.parse_args()

    with rosbag.Bag(a.bag) as bag:
        info = bag.get_type_and_topic_info()
        scans = sum(t.message_count for t in info.topics.values()
                    if t.msg_type == "sensor_msgs/LaserScan")
        bag_start = bag.get_start_time()
        bag_end = bag.get_end_time()
        last_tf = None  # the localisation keeps publishing after the lasers stop: resent at the end
        for _, msg, _ in bag.read_messages(topics=["/tf"],
                                           start_time=rospy.Time.from_sec(bag_end - 1.0)):
            last_tf = msg
    rospy.init_node("soak_sampler", disable_signals=True)
    lock = threading.Lock()
    last = {}
    samples = []  # (sim minutes, rss bytes, map bytes, received, integrated, dropped)

    errors = []  # rospy logs a callback's exception and goes on: counted here, failing the run

    def on_status(s):
        try:
            sample(s)
        except Exception as e:  # noqa: BLE001 - any error in a sample fails the soak
            errors.append(repr(e))

    def sample(s):
        t = s.header.stamp.to_sec() - bag_start
        with lock:
            last["status"] = s
            last["t"] = t
            minute = int(t // 60.0)
            if minute >= len(samples):
                received = sum(i.received for i in s.inputs)
                dropped = sum(dropped_of(i) for i in s.inputs)
                samples.append((t / 60.0, rss_bytes(a.pid), s.bytes, received,
                                s.scans_integrated, dropped))

    rospy.Subscriber("/wavog_mapping/status", MapperStatus, on_status, queue_size=10)
    played = os.path.join(a.out, "played")
    while not os.path.exists(played):
        time.sleep(0.5)
    # The bag's clock stopped: a few more simulated seconds for the last status.
    clock = rospy.Publisher("/clock", Clock, queue_size=10)
    tf_pub = rospy.Publisher("/tf", type(last_tf), queue_size=10) if last_tf else None
    time.sleep(1.0)  # connections
    t_end = bag_end
    for k in range(1, 41):
        now = rospy.Time.from_sec(t_end + 0.1 * k)
        clock.publish(Clock(clock=now))
        if tf_pub is not None:
            for t in last_tf.transforms:
                t.header.stamp = now
            tf_pub.publish(last_tf)
        time.sleep(0.05)
    time.sleep(1.0)
    with lock:
        s = last.get("status")
        if s is not None:
            received = sum(i.received for i in s.inputs)
            samples.append((last["t"] / 60.0, rss_bytes(a.pid), s.bytes, received,
                            s.scans_integrated, samples[-1][5] if samples else 0))
    if s is None:
        print("soak: no ~status received", file=sys.stderr)
        return 1
    integrated = s.scans_integrated
    lost = scans - integrated

    with open(os.path.join(a.out, "soak.csv"), "w") as f:
        f.write("sim_minutes,rss_bytes,map_bytes,received,integrated,dropped\n")
        for row in samples:
            f.write("%.3f,%d,%d,%d,%d,%d\n" % row)

    import numpy as np
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    m = np.array([r[0] for r in samples])
    rss = np.array([r[1] for r in samples]) / 2**20
    mb = np.array([r[2] for r in samples]) / 2**20
    fit = m >= 1.0
    def slope(y):
        if fit.sum() < 2:
            return float("nan")
        return float(np.polyfit(m[fit] / 60.0, y[fit], 1)[0])
    rss_slope, map_slope = slope(rss), slope(mb)
    fig, ax = plt.subplots(figsize=(8, 4.5))
    ax.plot(m, rss, "o-", label="node resident memory (MiB), %+.2f MiB/h" % rss_slope)
    ax.plot(m, mb, "s-", label="map bytes (MiB), %+.2f MiB/h" % map_slope)
    ax.set_xlabel("simulated time (min)")
    ax.set_ylabel("MiB")
    ax.set_ylim(bottom=0)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best")
    ax.set_title("make soak: car park, 4 x LMS-291 at 40 Hz, %.0f min at %gx, %d scans, %d lost"
                 % (m[-1], a.rate, scans, lost))
    fig.tight_layout()
    fig.savefig(os.path.join(a.out, "soak.png"), dpi=100)

    text = ("soak: %.1f simulated min at %gx: %d scans in the bag, %d received, %d integrated, "
            "%d lost\n"
            "soak: resident memory %.1f MiB at the end (%.1f after 1 min), slope %+.2f MiB/h\n"
            "soak: map bytes %.2f MiB at the end, slope %+.2f MiB/h\n"
            "soak: %s, %s, %s\n"
            % (m[-1], a.rate, scans, samples[-1][3], integrated, lost, rss[-1],
               rss[fit][0] if fit.any() else rss[0], rss_slope, mb[-1], map_slope,
               os.path.join(a.out, "soak.csv"), os.path.join(a.out, "soak.png"),
               os.path.join(a.out, "soak.txt")))
    with open(os.path.join(a.out, "soak.txt"), "w") as f:
        f.write(text)
    if errors:
        print("soak: %d status samples failed, the first: %s" % (len(errors), errors[0]),
              file=sys.stderr)
        return 1
    if m[-1] >= 2.0 and fit.sum() < 2:
        print("soak: %d samples over %.1f simulated min: too few for a slope" % (len(samples), m[-1]),
              file=sys.stderr)
        return 1
    return 1 if lost != 0 else 0


if __name__ == "__main__":
    sys.exit(main())
