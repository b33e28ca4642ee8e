#!/usr/bin/python3
"""Design (b) of issue 30 measured: what streaming one vehicle's map changes as blocks of Haar
coefficients (the native file's block encoding) would cost, on the fleet demo's car-park run.

One mapper per vehicle of VEHICLES (config/lms291_x4.yaml, each in its namespace) maps the fleet
bag (played in real time, private roscore); every PERIOD s of sim time each ~save_map writes the
native map. Between two
consecutive saves, the blocks that are new or whose encoding changed are what (b) would send in
that period (each block as the file writes it: i32 bx, i32 by, f64 average, u8 flags, its
coefficient subtree), plus 8 bytes (bx, by) per block removed. The sum over the run divided by the
run's length is (b)'s bytes per second, before any message framing. Writes OUT/design_b.json
(one entry per vehicle).

usage: fleet_design_b.py BIN_DIR SOURCE_DIR OUT BAG [VEHICLES (comma-separated)] [PERIOD]
"""
import json
import os
import shutil
import struct
import subprocess
import sys
import time

from fleet_common import free_port, stop_all, wait_for_master

BIN, SRC, OUT, BAG = sys.argv[1], sys.argv[2], os.path.abspath(sys.argv[3]), sys.argv[4]
VEHICLES = (sys.argv[5] if len(sys.argv) > 5 else "v1").split(",")
PERIOD = float(sys.argv[6]) if len(sys.argv) > 6 else 0.5

HEADER = 8 + 4 + 8 + 4 + 8 + 8  # magic, version, resolution, block_levels, prior, factor
# Per node: dx dy dxy (f64 from version 6, f32 in 5), u16 pending, u8 child_mask, known_all,
# known_any.
DETAIL_BYTES = {5: 4, 6: 8}


def blocks_of(path):
    """{(bx, by): the block's bytes as the file encodes it} of a native map (version 5 or 6)."""
    with open(path, "rb") as f:
        data = f.read()
    version = struct.unpack_from("<I", data, 8)[0] if len(data) >= 12 else None
    if data[:8] != b"WAVOGMAP" or version not in DETAIL_BYTES:
        raise RuntimeError(path + ": not a version 5 or 6 native map")
    details = 3 * DETAIL_BYTES[version]
    NODE = details + 2 + 1 + 1 + 1
    levels = struct.unpack_from("<i", data, 20)[0]
    count = struct.unpack_from("<Q", data, HEADER)[0]
    at = HEADER + 8

    def node(at, level):
        mask = data[at + details + 2]
        at += NODE
        if level > 1:
            for q in range(4):
                if mask & (1 << q):
                    at = node(at, level - 1)
        return at

    out = {}
    for _ in range(count):
        start = at
        bx, by = struct.unpack_from("<ii", data, at)
        flags = data[at + 16]
        at += 17
        if flags & 4:
            at = node(at, levels)
        out[(bx, by)] = data[start:at]
    return out


def record_snapshots(snap_dir):
    env = dict(os.environ)
    env["ROS_MASTER_URI"] = "http://127.0.0.1:%d" % free_port()
    env["ROS_HOSTNAME"] = "127.0.0.1"
    env.pop("ROS_IP", None)
    os.environ.update(env)
    procs = []

    def start(args):
        p = subprocess.Popen(args, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        procs.append(p)
        return p

    def param(*args):
        subprocess.run(["rosparam"] + list(args), env=env, check=True)

    snaps = []
    try:
        start(["roscore", "-p", env["ROS_MASTER_URI"].rsplit(":", 1)[1]])
        wait_for_master("/fleet_design_b")
        param("set", "/use_sim_time", "true")
        for v in VEHICLES:
            ns = "/%s/wavog_mapping" % v
            param("load", os.path.join(SRC, "config/lms291_x4.yaml"), ns)
            param("set", ns + "/publish_window", "0.0")
            param("set", ns + "/map_dir", snap_dir)
            start([os.path.join(BIN, "wavog_mapping_node"), "__ns:=/" + v,
                   "__name:=wavog_mapping"])
        import rospy
        from wavog_mapping.srv import SaveMap
        rospy.init_node("fleet_design_b", anonymous=True, disable_signals=True)
        saves = {}
        for v in VEHICLES:
            ns = "/%s/wavog_mapping" % v
            rospy.wait_for_service(ns + "/save_map", timeout=30)
            saves[v] = rospy.ServiceProxy(ns + "/save_map", SaveMap)

        def save(k):
            when = rospy.Time.now().to_sec()
            paths = {}
            for v in VEHICLES:
                name = "%s_%04d.wavog" % (v, k)
                r = saves[v](path=name)
                if not r.success:
                    raise RuntimeError(r.message)
                paths[v] = os.path.join(snap_dir, name)
            snaps.append((when, paths))
        play = start(["rosbag", "play", "--clock", "-q", BAG])
        while rospy.Time.now().is_zero() and play.poll() is None:
            time.sleep(0.01)
        t0 = rospy.Time.now().to_sec()
        k = 0
        while play.poll() is None:
            now = rospy.Time.now().to_sec()
            if now >= t0 + k * PERIOD:
                save(k)
                k += 1
            time.sleep(0.005)
        time.sleep(1.0)
        save(k)
    finally:
        stop_all(procs)
    return snaps


def measure(snaps, v):
    total = 0
    changed_blocks = 0
    periods = []
    prev = {}
    for _, paths in snaps:
        cur = blocks_of(paths[v])
        changed = [b for k, b in cur.items() if prev.get(k) != b]
        removed = [k for k in prev if k not in cur]
        size = sum(len(b) for b in changed) + 8 * len(removed)
        periods.append(size)
        total += size
        changed_blocks += len(changed)
        prev = cur
    span = snaps[-1][0] - snaps[0][0]
    return {
        "vehicle": v, "period_s": PERIOD, "span_s": span, "snapshots": len(snaps),
        "bytes": total, "bytes_per_s": total / span if span > 0 else None,
        "changed_blocks_per_period": changed_blocks / max(1, len(snaps) - 1),
        "final_blocks": len(prev), "final_blocks_bytes": sum(len(b) for b in prev.values()),
        "largest_period_bytes": max(periods) if periods else 0,
    }


def main():
    snap_dir = os.path.join(OUT, "design_b")
    os.makedirs(snap_dir, exist_ok=True)
    snaps = record_snapshots(snap_dir)
    report = [measure(snaps, v) for v in VEHICLES]
    with open(os.path.join(OUT, "design_b.json"), "w") as f:
        json.dump(report, f, indent=2)
    shutil.rmtree(snap_dir)
    print(json.dumps(report))


if __name__ == "__main__":
    main()
