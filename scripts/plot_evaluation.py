#!/usr/bin/env python3
"""Draws wavog_evaluate's figures from the data it writes.

Usage: /usr/bin/python3 scripts/plot_evaluation.py DIR

Reads DIR/figure_data/figures.json, DIR/figure_data/maps/*.png and DIR/figure_data/responses.csv
(written by wavog_evaluate) and writes, in DIR:
  policies.png    the final map of every policy side by side (x, y in metres)
  departure.png   the departed car's mean P(occupied) against time, one line per policy
  arrival.png     the same for the arrived car (further events: departure_<k>.png, ...)
  reflection_departure.png, reflection_arrival.png
                  with wavog_evaluate --reflection: the cars' mean reflection p the same way
  ndt_wall_distance.png
                  with wavog_evaluate --ndt (figure_data/ndt_wall_distance.csv): per policy the
                  mean distance to the true walls of the occupied cells' centres, of the centres
                  of those holding a Gaussian, and of their NDT means
Needs matplotlib (Debian: python3-matplotlib); `make demo` runs it.
"""

import csv
import json
import math
import os
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
from figure_common import DPI, run  # noqa: E402; sets matplotlib's display-less backend first

import matplotlib.image as mpimg  # noqa: E402
import matplotlib.patches as mpatches  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402

# One colour per policy, told apart on white (Okabe-Ito and darker shades).
PALETTE = ["#000000", "#e69f00", "#a06e00", "#56b4e9", "#005aa0", "#009e73", "#00643c",
           "#cc79a7", "#96326e", "#d55e00", "#787878"]
UNKNOWN = "#aac8eb"  # wavog::RenderOptions::unknown_colour (170, 200, 235)
COLUMNS = 3


def load(data_dir):
    with open(os.path.join(data_dir, "figures.json")) as f:
        figures = json.load(f)
    series, reflection = {}, {}
    with open(os.path.join(data_dir, "responses.csv"), newline="") as f:
        for row in csv.DictReader(f):
            key = (int(row["event"]), row["policy"])
            times, values = series.setdefault(key, ([], []))
            times.append(float(row["time_s"]))
            values.append(float(row["mean_p_occ"]))
            if row.get("mean_reflection_p"):  # wavog_evaluate --reflection
                rt, rv = reflection.setdefault(key, ([], []))
                rt.append(float(row["time_s"]))
                rv.append(float(row["mean_reflection_p"]))
    return figures, series, reflection


def plot_policies(figures, data_dir, out_path):
    maps = figures["maps"]
    rows = max(1, math.ceil(len(maps) / COLUMNS))
    x0, x1, y0, y1 = maps[0]["extent_m"] if maps else (0, 1, 0, 1)
    panel_w = 5.0
    panel_h = 0.85 * panel_w * (y1 - y0) / (x1 - x0) + 0.7  # the map, its title, the x label
    fig = plt.figure(figsize=(panel_w * COLUMNS, panel_h * rows + 1.2), constrained_layout=True)
    grid = fig.add_gridspec(rows + 1, COLUMNS, height_ratios=[0.5] + [panel_h] * rows)
    key = fig.add_subplot(grid[0, :])
    key.axis("off")
    key.legend(handles=[
        mpatches.Patch(facecolor="white", edgecolor="0.4", label="free (P(occupied) = 0)"),
        mpatches.Patch(facecolor="#7f7f7f", label="P = 0.5 (grey linear in P)"),
        mpatches.Patch(facecolor="black", label="occupied (P = 1)"),
        mpatches.Patch(facecolor=UNKNOWN, label="never observed")],
        loc="center", ncol=4, frameon=False, fontsize=11)
    for i, m in enumerate(maps):
        ax = fig.add_subplot(grid[1 + i // COLUMNS, i % COLUMNS])
        ax.imshow(mpimg.imread(os.path.join(data_dir, m["png"])), extent=m["extent_m"],
                  interpolation="nearest")
        ax.set_title(m["label"], fontsize=11)
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
    fig.suptitle("Final maps at t = %.0f s, %s, one per update policy / initial value"
                 % (figures["t_end_s"], figures["world"]), fontsize=13)
    fig.savefig(out_path, dpi=DPI)
    plt.close(fig)


def plot_event(k, event, figures, series, out_path, quantity="P(occupied)"):
    departure = event["type"] == "departure"
    fig, ax = plt.subplots(figsize=(10, 4.6), constrained_layout=True)
    t0 = max(0.0, event["start_s"] - 2.0)
    for i, m in enumerate(figures["maps"]):
        times, values = series.get((k, m["label"]), ([], []))
        # Runs that differ only in the initial value often coincide: dashed for empty_bound.
        style = "--" if m["label"].endswith("empty_bound") else "-"
        ax.plot(times, values, color=PALETTE[i % len(PALETTE)], linestyle=style, linewidth=1.6,
                label=m["label"])
    ax.axhline(0.5, color="0.55", linestyle="--", linewidth=1)
    ax.axvline(event["event_s"], color="0.55", linestyle=":", linewidth=1.2)
    ax.annotate("stall clear" if departure else "parked", xy=(event["event_s"], 1.0),
                xytext=(4, -14), textcoords="offset points", color="0.35")
    ax.set_xlim(t0, figures["t_end_s"])
    ax.set_ylim(-0.02, 1.02)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("mean %s of the car's cells" % quantity)
    ax.set_title("%s car '%s': mean %s of its %d cells against time"
                 % ("Departed" if departure else "Arrived", event["name"], quantity,
                    event["cells"]))
    ax.grid(True, color="0.9")
    ax.legend(title="policy / initial value", loc="center left", bbox_to_anchor=(1.01, 0.5),
              frameon=False)
    fig.savefig(out_path, dpi=DPI)
    plt.close(fig)


def plot_ndt(csv_path, resolution, out_path):
    with open(csv_path, newline="") as f:
        rows = list(csv.DictReader(f))
    bars = [("cell_centre_m", "occupied cells' centres", "#7f7f7f"),
            ("ndt_cell_centre_m", "centres of the cells with a Gaussian", "#56b4e9"),
            ("ndt_mean_m", "NDT means of those cells", "#d55e00")]
    width = 0.8 / len(bars)
    fig, ax = plt.subplots(figsize=(max(7.0, 1.3 * len(rows) + 3.0) + 3.5, 4.8),
                           constrained_layout=True)
    top = 0.0
    for j, (key, label, colour) in enumerate(bars):
        xs = [i + (j - (len(bars) - 1) / 2.0) * width for i in range(len(rows))]
        values = [100.0 * float(r[key]) for r in rows]  # "nan" where nothing was averaged
        top = max([top] + [v for v in values if math.isfinite(v)])
        ax.bar(xs, values, width, label=label, color=colour)
    ax.set_ylim(0.0, 1.15 * max(top, 50.0 * resolution if resolution else 0.0, 1.0))
    if resolution:
        ax.axhline(50.0 * resolution, color="0.35", linestyle="--", linewidth=1)
        ax.annotate("half a cell", xy=(len(rows) - 0.5, 50.0 * resolution), xytext=(-4, 4),
                    textcoords="offset points", ha="right", color="0.35")
    ax.set_xticks(range(len(rows)))
    ax.set_xticklabels([r["policy"] for r in rows], rotation=20, ha="right")
    ax.set_xlim(-0.6, len(rows) - 0.4)
    ax.set_ylabel("mean distance to the true walls (cm)")
    ax.set_title("Where the map puts the walls: cell centres against NDT means%s"
                 % (" (%.0f cm cells)" % (100.0 * resolution) if resolution else ""))
    ax.grid(True, axis="y", color="0.9")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    fig.savefig(out_path, dpi=DPI)
    plt.close(fig)


def draw(out_dir):
    data_dir = os.path.join(out_dir, "figure_data")
    figures, series, reflection = load(data_dir)
    written = [os.path.join(out_dir, "policies.png")]
    plot_policies(figures, data_dir, written[0])
    for k, event in enumerate(figures["events"]):
        written.append(os.path.join(out_dir, event["figure"]))
        plot_event(k, event, figures, series, written[-1])
        if any(key[0] == k for key in reflection):
            written.append(os.path.join(out_dir, "reflection_" + event["figure"]))
            plot_event(k, event, figures, reflection, written[-1], "reflection p")
    ndt_csv = os.path.join(data_dir, "ndt_wall_distance.csv")
    if os.path.exists(ndt_csv):  # wavog_evaluate --ndt
        resolution = None
        summary = os.path.join(out_dir, "summary.json")
        if os.path.exists(summary):
            with open(summary) as f:
                resolution = json.load(f).get("resolution")
        written.append(os.path.join(out_dir, "ndt_wall_distance.png"))
        plot_ndt(ndt_csv, resolution, written[-1])
    return written


if __name__ == "__main__":
    sys.exit(run(sys.argv, __doc__, draw))
