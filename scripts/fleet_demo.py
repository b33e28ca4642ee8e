#!/usr/bin/python3
"""make fleet-demo (issue 30): three simulated car-park vehicles, each mapper in its own process and
namespace streaming its placed scans (fleet_stream), one wavog_fleet node, over a private roscore.

Writes into OUT: fleet3.bag (wavog_simulate --vehicles 3), fleet.* and v<k>.* (the maps saved by
~save_map: native map + map_server images), fleet_vs_vehicles.png (side by side), report.md and
report.json with the bandwidth per vehicle (the stream, design (b)'s changed Haar blocks measured
by fleet_design_b.py in a second playback, the vehicle's OccupancyGrid layers and map_updates as
published, its raw LaserScans), the fleet node's CPU per vehicle-second and the lag from a scan's
stamp to the fleet map (integration, and the layers' publication).

usage: fleet_demo.py BIN_DIR SOURCE_DIR OUT [DURATION]
"""
import json
import os
import struct
import subprocess
import sys
import time

from fleet_common import cpu_seconds, free_port, stop_all, wait_for_master

BIN, SRC, OUT = sys.argv[1], sys.argv[2], os.path.abspath(sys.argv[3])
DURATION = float(sys.argv[4]) if len(sys.argv) > 4 else 30.0
VEHICLES = ["v1", "v2", "v3"]
EPOCH = 1.7e9


def main():
    os.makedirs(OUT, exist_ok=True)
    bag = os.path.join(OUT, "fleet3.bag")
    print("fleet-demo: [1/5] simulating 3 vehicles in the car park, %.0f s" % DURATION, flush=True)
    subprocess.run([os.path.join(BIN, "wavog_simulate"), "--vehicles", "3", "--duration",
                    str(DURATION), "--seed", "1", "--out", bag], check=True,
                   stderr=subprocess.DEVNULL)
    env = dict(os.environ)
    env["ROS_MASTER_URI"] = "http://127.0.0.1:%d" % free_port()
    env["ROS_HOSTNAME"] = "127.0.0.1"
    env.pop("ROS_IP", None)
    os.environ.update(env)
    procs = []

    def start(args, **kw):
        p = subprocess.Popen(args, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                             **kw)
        procs.append(p)
        return p

    try:
        port = env["ROS_MASTER_URI"].rsplit(":", 1)[1]
        start(["roscore", "-p", port])
        wait_for_master("/fleet_demo")
        subprocess.run(["rosparam", "set", "/use_sim_time", "true"], env=env, check=True)
        subprocess.run(["rosparam", "load", os.path.join(SRC, "config/fleet.yaml"), "/wavog_fleet"],
                       env=env, check=True)
        subprocess.run(["rosparam", "set", "/wavog_fleet/map_dir", OUT], env=env, check=True)
        for v in VEHICLES:
            ns = "/%s/wavog_mapping" % v
            subprocess.run(["rosparam", "load", os.path.join(SRC, "config/lms291_x4.yaml"), ns],
                           env=env, check=True)
            for key, value in [("fleet_stream", "true"), ("publish_window", "0.0"),
                               ("map_dir", OUT)]:
                subprocess.run(["rosparam", "set", ns + "/" + key, value], env=env, check=True)
        fleet = start([os.path.join(BIN, "wavog_fleet"), "__name:=wavog_fleet"])
        for v in VEHICLES:
            start([os.path.join(BIN, "wavog_mapping_node"), "__ns:=/" + v, "__name:=wavog_mapping"])

        import rospy
        from rospy.msg import AnyMsg
        from wavog_mapping.msg import FleetStatus
        rospy.init_node("fleet_demo", anonymous=True)
        counts = {}

        def counter(topic):
            counts[topic] = 0

            def cb(msg):
                counts[topic] += len(msg._buff)
            return rospy.Subscriber(topic, AnyMsg, cb, queue_size=10000)

        subs = []
        for v in VEHICLES:
            for t in ["fleet_scans", "map", "map_scale_2", "map_scale_3", "map_scale_4",
                      "map_updates", "scan_front_left", "scan_front_right", "scan_rear_left",
                      "scan_rear_right"]:
                subs.append(counter("/%s/%s" % (v, t)))
        lags = []
        lag_maxes = []
        publish_lag_maxes = []
        last = {}

        def on_status(s):
            last["status"] = s
            for v in s.vehicles:
                if v.integrated > 0 and not v.stale:
                    lags.append(v.lag)
                    lag_maxes.append(v.lag_max)
                    if v.publish_lag_max > 0:
                        publish_lag_maxes.append(v.publish_lag_max)
        subs.append(rospy.Subscriber("/wavog_fleet/fleet_status", FleetStatus, on_status))
        for v in VEHICLES:
            rospy.wait_for_service("/%s/wavog_mapping/save_map" % v, timeout=30)
        rospy.wait_for_service("/wavog_fleet/save_map", timeout=30)
        time.sleep(1.0)
        print("fleet-demo: [2/5] playing it: 3 mappers streaming, one fleet node", flush=True)
        cpu0 = cpu_seconds(fleet.pid)
        wall0 = time.time()
        subprocess.run(["rosbag", "play", "--clock", "-q", bag], env=env, check=True)
        wall = time.time() - wall0
        # The mappers flush what waits for tf after idle_timeout (2 s), and the fleet node's last
        # scans wait until the streams have been silent for fleet_stale_timeout (2 s).
        time.sleep(5.0)
        cpu = cpu_seconds(fleet.pid) - cpu0
        print("fleet-demo: [3/5] saving the maps", flush=True)
        from wavog_mapping.srv import SaveMap
        for name, service in [("fleet", "/wavog_fleet/save_map")] + [
                (v, "/%s/wavog_mapping/save_map" % v) for v in VEHICLES]:
            r = rospy.ServiceProxy(service, SaveMap)(path=name + ".wavog")
            if not r.success:
                raise RuntimeError(service + ": " + r.message)
        status = last["status"]
    finally:
        stop_all(procs)

    print("fleet-demo: [4/5] design (b) measured: each vehicle's changed map blocks every 0.5 s "
          "(one more playback)", flush=True)
    subprocess.run(["/usr/bin/python3", os.path.join(SRC, "scripts/fleet_design_b.py"), BIN, SRC,
                    OUT, bag, ",".join(VEHICLES), "0.5"], check=True, stdout=subprocess.DEVNULL,
                   stderr=subprocess.DEVNULL)
    with open(os.path.join(OUT, "design_b.json")) as f:
        design_b = {d["vehicle"]: d for d in json.load(f)}
    with open(os.path.join(OUT, VEHICLES[0] + ".wavog"), "rb") as f:
        block_side = 2 ** struct.unpack_from("<i", f.read(24), 20)[0]  # the header's block_levels
    print("fleet-demo: [5/5] figure and report", flush=True)
    rows = []
    for v in VEHICLES:
        def rate(topics):
            return sum(counts["/%s/%s" % (v, t)] for t in topics) / DURATION
        stream = rate(["fleet_scans"])
        layers = rate(["map", "map_scale_2", "map_scale_3", "map_scale_4", "map_updates"])
        scans = rate(["scan_front_left", "scan_front_right", "scan_rear_left", "scan_rear_right"])
        rows.append({"vehicle": v, "stream_Bps": stream, "layers_Bps": layers, "laserscans_Bps": scans,
                     "haar_blocks_Bps": design_b[v]["bytes_per_s"],
                     "haar_blocks_changed_per_period": design_b[v]["changed_blocks_per_period"],
                     "haar_blocks_final": design_b[v]["final_blocks"]})
    vs = status.vehicles
    integrated = sum(v.integrated for v in vs)
    lags_sorted = sorted(lags)
    report = {
        "duration_s": DURATION, "wall_s": wall, "vehicles": rows,
        "fleet_cpu_s": cpu, "fleet_cpu_per_vehicle_second": cpu / (len(VEHICLES) * DURATION),
        "scans_integrated": integrated,
        "late": sum(v.integrated_late + v.dropped_late for v in vs),
        "refused": sum(v.dropped_version + v.dropped_frame + v.dropped_bad_pose + v.dropped_bad_size
                       + v.dropped_refused + v.dropped_overflow for v in vs),
        "lag_median_s": lags_sorted[len(lags_sorted) // 2] if lags else None,
        "lag_max_s": max(lag_maxes) if lag_maxes else None,
        "publish_lag_period_max_median_s": (sorted(publish_lag_maxes)[len(publish_lag_maxes) // 2]
                                            if publish_lag_maxes else None),
        "publish_lag_max_s": max(publish_lag_maxes) if publish_lag_maxes else None,
        "publish_rate_hz": 2.0,
        "reorder_wait_s": status.reorder_wait,
    }
    with open(os.path.join(OUT, "report.json"), "w") as f:
        json.dump(report, f, indent=2)

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    def pgm(path):
        with open(path, "rb") as f:
            data = f.read()
        parts = data.split(maxsplit=4)
        w, h, _ = int(parts[1]), int(parts[2]), int(parts[3])
        return np.frombuffer(parts[4][:w * h], dtype=np.uint8).reshape(h, w)

    names = ["fleet"] + VEHICLES
    fig, axes = plt.subplots(1, 4, figsize=(20, 6))
    for ax, name in zip(axes, names):
        img = pgm(os.path.join(OUT, name + "_s0.pgm"))
        meta = {}
        with open(os.path.join(OUT, name + "_s0.yaml")) as f:
            for line in f:
                if ":" in line:
                    k, v = line.split(":", 1)
                    meta[k.strip()] = v.strip()
        res = float(meta["resolution"])
        x0, y0 = [float(t) for t in meta["origin"].strip("[]").split(",")[:2]]
        h, w = img.shape
        ax.imshow(img, cmap="gray", vmin=0, vmax=255, extent=(x0, x0 + w * res, y0, y0 + h * res))
        ax.set_xlim(-4, 74)
        ax.set_ylim(-4, 38)
        ax.set_title("fleet map (3 vehicles)" if name == "fleet" else "vehicle " + name)
        ax.set_xlabel("x (m)")
    fig.tight_layout()
    fig.savefig(os.path.join(OUT, "fleet_vs_vehicles.png"), dpi=80)

    lines = ["# Fleet demo (make fleet-demo)", "",
             "Three simulated vehicles in the car park (wavog_simulate --vehicles 3, %.0f s, four "
             "LMS-291 each at 40 Hz), each mapper (config/lms291_x4.yaml, fleet_stream: true) in "
             "its own process and namespace, one wavog_fleet (config/fleet.yaml), one roscore, "
             "measured in one run (wall %.1f s on this machine)." % (DURATION, wall), "",
             "## Bandwidth per vehicle (bytes/s, serialized, as received over TCPROS)", "",
             "| vehicle | (a) placed-scan stream (chosen) | (b) changed Haar blocks every 0.5 s | OccupancyGrid layers + map_updates | raw LaserScans | (a) / layers | (b) / layers |",
             "|---|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        lines.append("| %s | %.0f | %.0f | %.0f | %.0f | %.2f | %.2f |" % (
            r["vehicle"], r["stream_Bps"], r["haar_blocks_Bps"], r["layers_Bps"],
            r["laserscans_Bps"],
            r["stream_Bps"] / r["layers_Bps"] if r["layers_Bps"] else float("nan"),
            r["haar_blocks_Bps"] / r["layers_Bps"] if r["layers_Bps"] else float("nan")))
    lines += ["",
              "Layers: the mapper's map, map_scale_2/3/4 at publish_rate 2 Hz and map_updates at "
              "5 Hz, as config/lms291_x4.yaml publishes them (whole map, publish_window 0).", "",
              "(b): the same bag mapped again by the same mappers (scripts/fleet_design_b.py), "
              "each saved every 0.5 s of sim time; per period, the blocks new or changed since the "
              "previous save, in the native file's block encoding (coordinates, average, flags, "
              "coefficient subtree), plus 8 bytes per removed block, summed over the run / its "
              "length; no message framing. A block here is %d x %d cells at 0.1 m; each vehicle's "
              "map ends with %s blocks, and %s of them changed per period on average, so (b) "
              "resends most of the observed map every period." % (
                  block_side, block_side, "/".join(str(r["haar_blocks_final"]) for r in rows),
                  "/".join("%.1f" % r["haar_blocks_changed_per_period"] for r in rows)), "",
              "## Fleet node", "",
              "- scans integrated: %d; late: %d; refused: %d" % (integrated, report["late"], report["refused"]),
              "- CPU: %.2f s for %d vehicle-seconds = %.4f s per vehicle-second (%.1f %% of a core per vehicle)" % (
                  cpu, len(VEHICLES) * DURATION, report["fleet_cpu_per_vehicle_second"],
                  100 * report["fleet_cpu_per_vehicle_second"]),
              "- lag from a scan's stamp to its integration into the fleet map (sampled at each ~fleet_status): median %.3f s, max %.3f s "
              "(fleet_reorder_wait %.1f s dominates)" % (
                  report["lag_median_s"] or 0, report["lag_max_s"] or 0, status.reorder_wait),
              "- lag from a scan's stamp to the first publication of the fleet map's layers that "
              "include it (VehicleStatus.publish_lag_max, the largest per publish period): median "
              "over periods %.3f s, max %.3f s (the integration lag plus up to 1 / publish_rate = "
              "%.1f s)" % (report["publish_lag_period_max_median_s"] or 0,
                           report["publish_lag_max_s"] or 0, 1.0 / report["publish_rate_hz"]),
              "", "Figure: fleet_vs_vehicles.png (fleet map, then each vehicle's own map)."]
    with open(os.path.join(OUT, "report.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
