#!/usr/bin/python3
"""make fleet-bench (issue 30): does one wavog_fleet keep up with 8 vehicles on one core?

1. wavog_simulate --vehicles 8 (car park, four LMS-291 at 40 Hz each) -> OUT/sim8.bag.
2. Eight mappers (config/lms291_x4.yaml, fleet_stream: true), each in its own process and
   namespace, map it (played at RECORD_RATE so that eight mappers keep up on this machine);
   rosbag record keeps their PlacedScan streams -> OUT/fleet8.bag, the recorded fleet bag.
3. For each playback rate k: a fresh wavog_fleet (config/fleet.yaml, fleet_vehicles v1..v8),
   rosbag play -r k fleet8.bag into it; the fleet node's CPU time (/proc) over the playback, and
   whether it kept up: every recorded scan integrated, nothing late, lost, refused or overflowing,
   and the integration rate (scans integrated / wall s) at least the arrival rate.

Writes OUT/bench.md and OUT/bench.json. usage: fleet_bench.py BIN_DIR SOURCE_DIR OUT [DURATION]
[RATES]  (RATES: comma-separated playback rates, default 1,2,4)
"""
import json
import os
import subprocess
import sys
import time

from fleet_common import RosGraph, cpu_seconds, stop_all

BIN, SRC, OUT = sys.argv[1], sys.argv[2], os.path.abspath(sys.argv[3])
DURATION = float(sys.argv[4]) if len(sys.argv) > 4 else 20.0
RATES = [float(r) for r in sys.argv[5].split(",")] if len(sys.argv) > 5 else [1.0, 2.0, 4.0]
N = 8
VEHICLES = ["v%d" % (k + 1) for k in range(N)]
RECORD_RATE = 0.5


class Graph(RosGraph):
    """A private roscore and the processes started under it."""

    def __init__(self):
        super().__init__("/fleet_bench")

    def wait_for(self, topic_or_service, service=True, timeout=30.0):
        import rosgraph
        master = rosgraph.Master("/fleet_bench")
        t0 = time.time()
        while time.time() - t0 < timeout:
            try:
                if service:
                    master.lookupService(topic_or_service)
                    return
            except Exception:
                pass
            time.sleep(0.2)
        raise RuntimeError("no " + topic_or_service)

    def stop(self, p):
        stop_all([p])

    def close(self):
        for p in reversed(self.procs):
            if p.poll() is None:
                self.stop(p)


def record_fleet_bag(g, sim_bag, fleet_bag):
    mappers = []
    try:
        for v in VEHICLES:
            ns = "/%s/wavog_mapping" % v
            g.param("load", os.path.join(SRC, "config/lms291_x4.yaml"), ns)
            g.param("set", ns + "/fleet_stream", "true")
            g.param("set", ns + "/publish_window", "0.0")
        for v in VEHICLES:
            mappers.append(g.start([os.path.join(BIN, "wavog_mapping_node"), "__ns:=/" + v,
                                    "__name:=wavog_mapping"]))
        for v in VEHICLES:
            g.wait_for("/%s/wavog_mapping/save_map" % v)
        rec = g.start(["rosbag", "record", "-q", "-O", fleet_bag]
                      + ["/%s/fleet_scans" % v for v in VEHICLES])
        time.sleep(3.0)  # rosbag record subscribes
        subprocess.run(["rosbag", "play", "--clock", "-q", "-r", str(RECORD_RATE), sim_bag],
                       env=g.env, check=True)
        time.sleep(3.0)
        g.stop(rec)
    finally:
        for p in mappers:
            g.stop(p)


def bag_count(bag):
    import rosbag
    with rosbag.Bag(bag) as b:
        info = b.get_type_and_topic_info()
        return sum(t.message_count for t in info.topics.values()), b.get_end_time() - b.get_start_time()


def play_into_fleet(g, fleet_bag, rate):
    fleet = None
    try:
        g.param("load", os.path.join(SRC, "config/fleet.yaml"), "/wavog_fleet")
        g.param("set", "/wavog_fleet/fleet_vehicles", "[%s]" % ", ".join(VEHICLES))
        fleet = g.start([os.path.join(BIN, "wavog_fleet"), "__name:=wavog_fleet"])
        g.wait_for("/wavog_fleet/save_map")
        import rospy
        from wavog_mapping.msg import FleetStatus
        if not rospy.core.is_initialized():
            rospy.init_node("fleet_bench", anonymous=True, disable_signals=True)
        last = {}
        sub = rospy.Subscriber("/wavog_fleet/fleet_status", FleetStatus,
                               lambda s: last.__setitem__("status", s))
        time.sleep(2.0)  # the fleet node's subscriptions connect
        cpu0 = cpu_seconds(fleet.pid)
        wall0 = time.time()
        subprocess.run(["rosbag", "play", "--clock", "-q", "-r", str(rate), fleet_bag],
                       env=g.env, check=True)
        wall = time.time() - wall0
        # The scans still in flight or buffered are counted in: the last ones wait until the
        # streams have been silent for fleet_stale_timeout (2 s), then fleet_reorder_wait (0.3 s).
        time.sleep(3.0)
        cpu_play = cpu_seconds(fleet.pid) - cpu0
        # The last fleet_status: the clock stopped with the bag, and save_map publishes it.
        from wavog_mapping.srv import SaveMap
        rospy.ServiceProxy("/wavog_fleet/save_map", SaveMap)(path="bench_%g.wavog" % rate)
        time.sleep(1.0)
        status = last.get("status")
        sub.unregister()
        return wall, cpu_play, status
    finally:
        if fleet is not None:
            g.stop(fleet)


def main():
    os.makedirs(OUT, exist_ok=True)
    sim_bag = os.path.join(OUT, "sim8.bag")
    fleet_bag = os.path.join(OUT, "fleet8.bag")
    print("fleet-bench: [1/3] simulating %d vehicles in the car park, %.0f s" % (N, DURATION),
          flush=True)
    subprocess.run([os.path.join(BIN, "wavog_simulate"), "--vehicles", str(N), "--duration",
                    str(DURATION), "--seed", "1", "--out", sim_bag], check=True,
                   stderr=subprocess.DEVNULL)
    print("fleet-bench: [2/3] %d mappers streaming, recorded into fleet8.bag (played at %g x)"
          % (N, RECORD_RATE), flush=True)
    g = Graph()
    try:
        record_fleet_bag(g, sim_bag, fleet_bag)
        runs = bench(g, fleet_bag)
    finally:
        g.close()
    report(runs, fleet_bag)


def bench(g, fleet_bag):
    messages, span = bag_count(fleet_bag)
    runs = []
    for rate in RATES:
        print("fleet-bench: [3/3] fleet8.bag at %g x into one wavog_fleet" % rate, flush=True)
        wall, cpu, s = play_into_fleet(g, fleet_bag, rate)
        vs = s.vehicles if s else []
        integrated = sum(v.integrated for v in vs)
        late = sum(v.integrated_late + v.dropped_late for v in vs)
        lost = sum(v.lost for v in vs)
        refused = sum(v.dropped_version + v.dropped_frame + v.dropped_bad_pose + v.dropped_bad_size
                      + v.dropped_refused + v.dropped_overflow for v in vs)
        received = sum(v.received for v in vs)
        run = {"rate": rate, "wall_s": wall, "cpu_s": cpu, "core_fraction": cpu / wall,
               "vehicle_seconds": N * span,
               "cpu_per_vehicle_second": cpu / (N * span),
               "messages_in_bag": messages, "received": received, "integrated": integrated,
               "late": late, "lost": lost, "refused": refused,
               "arrival_rate_per_s": messages / wall, "integration_rate_per_s": integrated / wall,
               "buffered_at_end": s.buffered if s else None}
        run["kept_up"] = (integrated == messages and late == 0 and lost == 0 and refused == 0
                          and cpu < wall)
        runs.append(run)
        print("  %s" % json.dumps(run), flush=True)
    return runs


def report(runs, fleet_bag):
    messages, span = bag_count(fleet_bag)
    report = {"vehicles": N, "duration_s": DURATION, "fleet_bag_span_s": span,
              "fleet_bag_messages": messages, "record_rate": RECORD_RATE, "runs": runs}
    with open(os.path.join(OUT, "bench.json"), "w") as f:
        json.dump(report, f, indent=2)
    lines = ["# Fleet bench (make fleet-bench)", "",
             "One wavog_fleet (config/fleet.yaml) fed a recorded fleet bag: the PlacedScan streams "
             "of %d simulated car-park vehicles (wavog_simulate --vehicles %d, %.0f s, four LMS-291 "
             "each at 40 Hz; each mapped by its own wavog_mapping_node with fleet_stream: true, "
             "config/lms291_x4.yaml), %d scans over %.1f s, played with rosbag play -r k. CPU: the "
             "fleet node's user + system time (/proc) over the playback; kept up: every scan "
             "integrated, none late, lost or refused, and CPU < wall (under one core)."
             % (N, N, DURATION, messages, span), "",
             "| rate k | wall s | fleet CPU s | share of one core | CPU s per vehicle-second | "
             "arrival scans/s | integrated scans/s | integrated / in bag | late | lost | refused "
             "| kept up |",
             "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|"]
    for r in runs:
        lines.append("| %g | %.1f | %.2f | %.0f %% | %.4f | %.0f | %.0f | %d / %d | %d | %d | %d "
                     "| %s |" % (r["rate"], r["wall_s"], r["cpu_s"], 100 * r["core_fraction"],
                                 r["cpu_per_vehicle_second"], r["arrival_rate_per_s"],
                                 r["integration_rate_per_s"], r["integrated"],
                                 r["messages_in_bag"], r["late"], r["lost"], r["refused"],
                                 "yes" if r["kept_up"] else "no"))
    kept = [r["rate"] for r in runs if r["kept_up"]]
    lines += ["", "Largest rate kept up: %s. Rate k = 1 is %d vehicles in real time; k = 2 is %d "
              "vehicles' worth of scans per second. Scans missing from \"received\" were dropped "
              "on the way (rosbag play's publisher queue once the node fell behind). The layers "
              "(publish_rate 2 Hz, whole map) follow sim time, so at rate k they are published k "
              "times as often per wall second and their cost is included."
              % ("%g x (%d vehicle-equivalents)" % (max(kept), int(max(kept) * N)) if kept
                 else "none", N, 2 * N)]
    with open(os.path.join(OUT, "bench.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
