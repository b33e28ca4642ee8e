#!/usr/bin/python3
"""make fleet-shard-bench (issue 36): how many vehicles do 1, 2 and 4 region shards keep up with?

1. wavog_simulate --placed-scans --vehicles N (car park, four LMS-291 at 40 Hz each): the fleet
   bag of N vehicles' placed-scan streams at their true sensor poses (what their mappers stream),
   for each N in VEHICLES.
2. For each N, shard count S and playback rate k: S fresh wavog_fleet nodes (config/fleet.yaml,
   block_levels 7: blocks of 12.8 m; S = 1 without a region, S = 2 split at x = 38.4 m, S = 4 at
   25.6, 38.4 and 51.2 m), rosbag play -r k into them; per shard its CPU time (/proc) over the
   playback, its largest lag_max, and whether it kept up: every scan integrated, nothing late,
   lost or refused, CPU < wall.
3. The stream's bytes per placed scan, serialised, as the mappers send it by default (16-bit range
   codes, fleet_stream_format: uint16, which the bags of 1. hold) and as float32 (version 1):
   wavog_simulate's own count over the smallest N's streams in either format.

Writes OUT/shard_bench.md and OUT/shard_bench.json. usage: fleet_shard_bench.py BIN_DIR SOURCE_DIR
OUT [DURATION] [VEHICLES] [SHARDS] [RATES] (comma-separated lists; defaults 10, 8,16,32, 1,2,4,
1,2)
"""
import json
import os
import subprocess
import sys
import time

from fleet_common import RosGraph, cpu_seconds, stop_all

BIN, SRC, OUT = sys.argv[1], sys.argv[2], os.path.abspath(sys.argv[3])
DURATION = float(sys.argv[4]) if len(sys.argv) > 4 else 10.0
VEHICLES = [int(v) for v in sys.argv[5].split(",")] if len(sys.argv) > 5 else [8, 16, 32]
SHARDS = [int(v) for v in sys.argv[6].split(",")] if len(sys.argv) > 6 else [1, 2, 4]
RATES = [float(r) for r in sys.argv[7].split(",")] if len(sys.argv) > 7 else [1.0, 2.0]
BLOCK = 12.8  # m: 0.1 m x 2^7
FAR = 1024 * BLOCK
SPLITS = {1: [], 2: [38.4], 4: [25.6, 38.4, 51.2]}


def regions(shards):
    """The shards' fleet_region values: strips along x, at SPLITS."""
    if shards == 1:
        return [[]]
    xs = [-FAR] + SPLITS[shards] + [FAR]
    return [[xs[i], -FAR, xs[i + 1], FAR] for i in range(shards)]


class Graph(RosGraph):
    """A private roscore and the processes started under it."""

    def __init__(self):
        super().__init__("/fleet_shard_bench")

    def wait_for_service(self, name, timeout=30.0):
        import rosgraph
        master = rosgraph.Master("/fleet_shard_bench")
        t0 = time.time()
        while time.time() - t0 < timeout:
            try:
                master.lookupService(name)
                return
            except Exception:
                time.sleep(0.2)
        raise RuntimeError("no " + name)

    def close(self):
        stop_all([p for p in self.procs if p.poll() is None])


def bag_info(bag):
    import rosbag
    with rosbag.Bag(bag) as b:
        info = b.get_type_and_topic_info()
        n = sum(t.message_count for name, t in info.topics.items() if name.endswith("fleet_scans"))
        size = os.path.getsize(bag)
        return n, b.get_end_time() - b.get_start_time(), size


def run(g, bag, n, shards, rate):
    import rospy
    from wavog_mapping.msg import FleetStatus
    vehicles = ["v%d" % (k + 1) for k in range(n)]
    nodes, subs = [], []
    last = [dict(lag=0.0) for _ in range(shards)]
    try:
        for i, region in enumerate(regions(shards)):
            ns = "/s%d/wavog_fleet" % i
            g.param("load", os.path.join(SRC, "config/fleet.yaml"), ns)
            g.param("set", ns + "/fleet_vehicles", "[%s]" % ", ".join("/" + v for v in vehicles))
            g.param("set", ns + "/block_levels", "7")
            g.param("set", ns + "/publish_scales", "[3]")
            g.param("set", ns + "/map_dir", OUT)  # ~save_map writes there
            g.param("set", ns + "/fleet_region", "[%s]" % ", ".join("%g" % x for x in region))
            nodes.append(g.start([os.path.join(BIN, "wavog_fleet"), "__ns:=/s%d" % i,
                                  "__name:=wavog_fleet"]))
        for i in range(shards):
            g.wait_for_service("/s%d/wavog_fleet/save_map" % i)
        if not rospy.core.is_initialized():
            rospy.init_node("fleet_shard_bench", anonymous=True, disable_signals=True)

        def on_status(i):
            def cb(s):
                last[i]["status"] = s
                last[i]["lag"] = max([last[i]["lag"]] + [v.lag_max for v in s.vehicles])
            return cb
        for i in range(shards):
            subs.append(rospy.Subscriber("/s%d/wavog_fleet/fleet_status" % i, FleetStatus,
                                         on_status(i)))
        time.sleep(2.0 + 0.05 * n)  # the fleet nodes' subscriptions connect
        cpu0 = [cpu_seconds(p.pid) for p in nodes]
        wall0 = time.time()
        # -d: rosbag play waits after advertising, so that every shard has connected to every
        # vehicle topic before the first scan (else the first scans miss a shard on a busy host).
        delay = 1.0 + 0.05 * n * shards
        subprocess.run(["rosbag", "play", "--clock", "-q", "-d", "%g" % delay, "-r", str(rate),
                        bag], env=g.env, check=True)
        wall = time.time() - wall0 - delay
        # What is in flight or buffered: the last scans wait until the streams have been silent
        # for fleet_stale_timeout (2 s), then fleet_reorder_wait (0.3 s).
        time.sleep(3.0)
        cpu = [cpu_seconds(p.pid) - c for p, c in zip(nodes, cpu0)]
        from wavog_mapping.srv import SaveMap
        for i in range(shards):  # publishes the last fleet_status (the clock stopped)
            rospy.ServiceProxy("/s%d/wavog_fleet/save_map" % i, SaveMap)(
                path="shard%d.wavog" % i)
        time.sleep(1.0)
        out = []
        for i in range(shards):
            s = last[i].get("status")
            if s is None:
                print("  shard %d: no fleet_status received" % i, flush=True)
            vs = s.vehicles if s else []
            out.append({
                "cpu_s": cpu[i], "core_fraction": cpu[i] / wall,
                "integrated": sum(v.integrated for v in vs),
                "outside_region": sum(v.outside_region for v in vs),
                "late": sum(v.integrated_late + v.dropped_late for v in vs),
                "lost": sum(v.lost for v in vs),
                "refused": sum(v.dropped_version + v.dropped_frame + v.dropped_bad_pose
                               + v.dropped_bad_size + v.dropped_refused + v.dropped_overflow
                               for v in vs),
                "lag_max_s": last[i]["lag"]})
        return wall, out
    finally:
        for s in subs:
            s.unregister()
        stop_all(nodes)


def stream_bytes(n):
    """Serialised bytes per placed scan of n vehicles' streams, per fleet_stream_format."""
    out = {}
    for fmt in ("float32", "uint16"):
        bag = os.path.join(OUT, "bytes_%s.bag" % fmt)
        p = subprocess.run([os.path.join(BIN, "wavog_simulate"), "--vehicles", str(n),
                            "--duration", str(DURATION), "--seed", "1", "--placed-scans",
                            "--placed-format", fmt, "--out", bag], check=True,
                           stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                           universal_newlines=True)
        os.remove(bag)
        for line in p.stderr.splitlines():
            if "bytes per scan serialised" in line:
                out[fmt] = float(line.split("): ")[1].split()[0])
    return out


def main():
    os.makedirs(OUT, exist_ok=True)
    g = Graph()
    runs = []
    per_scan = stream_bytes(min(VEHICLES))
    print("fleet-shard-bench: stream bytes per scan %s" % json.dumps(per_scan), flush=True)
    try:
        for n in VEHICLES:
            bag = os.path.join(OUT, "placed%d.bag" % n)
            subprocess.run([os.path.join(BIN, "wavog_simulate"), "--vehicles", str(n),
                            "--duration", str(DURATION), "--seed", "1", "--placed-scans",
                            "--out", bag], check=True, stderr=subprocess.DEVNULL)
            messages, span, size = bag_info(bag)
            for shards in SHARDS:
                for rate in RATES:
                    print("fleet-shard-bench: %d vehicles, %d shard(s), %g x" % (n, shards, rate),
                          flush=True)
                    wall, per = run(g, bag, n, shards, rate)
                    kept = all(p["integrated"] == messages and p["late"] == 0 and p["lost"] == 0
                               and p["refused"] == 0 and p["cpu_s"] < wall for p in per)
                    r = {"vehicles": n, "shards": shards, "rate": rate, "wall_s": wall,
                         "messages": messages, "bag_span_s": span,
                         "bytes_per_scan": size / messages, "shards_detail": per, "kept_up": kept}
                    runs.append(r)
                    print("  %s" % json.dumps(r), flush=True)
            os.remove(bag)
    finally:
        g.close()
    with open(os.path.join(OUT, "shard_bench.json"), "w") as f:
        json.dump({"duration_s": DURATION, "stream_bytes_per_scan": per_scan, "runs": runs}, f,
                  indent=2)
    lines = ["# Region shards bench (make fleet-shard-bench)", "",
             "N simulated car-park vehicles' placed-scan streams (wavog_simulate --placed-scans, "
             "%g s, four LMS-291 at 40 Hz each) played with rosbag play -r k into S wavog_fleet "
             "nodes (config/fleet.yaml, 10 cm, blocks of 12.8 m; strips along x), all on this "
             "machine. Per shard: CPU share of one core over the playback, scans integrated "
             "(of the bag) and of those outside its region, late / lost / refused, largest lag "
             "(s). Kept up: every shard integrated every scan, none late, lost or refused, each "
             "under one core." % DURATION, "",
             "| vehicles | shards | rate | per shard: CPU share, outside region, late/lost/refused, "
             "lag max | kept up |", "|---:|---:|---:|---|---|"]
    lines[4:4] = ["The stream per LMS-291 placed scan (361 beams), serialised: %.0f bytes with "
                  "float32 ranges (fleet_stream_format: float32, version 1), %.0f bytes with "
                  "16-bit codes (uint16, version 2, the default, which these bags hold)."
                  % (per_scan["float32"], per_scan["uint16"]), ""]  # after the paragraph
    for r in runs:
        cells = "; ".join("%.0f %%, %d of %d out, %d/%d/%d, %.2f s"
                          % (100 * p["core_fraction"], p["outside_region"], p["integrated"],
                             p["late"], p["lost"], p["refused"], p["lag_max_s"])
                          for p in r["shards_detail"])
        lines.append("| %d | %d | %g | %s | %s |" % (r["vehicles"], r["shards"], r["rate"], cells,
                                                     "yes" if r["kept_up"] else "no"))
    with open(os.path.join(OUT, "shard_bench.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
