#!/usr/bin/env python3
"""Draws wavog_compare's disagreement figures from the pictures it writes.

Usage: /usr/bin/python3 scripts/plot_compare.py DIR

Reads DIR/pictures.json and the disagree_*.png it lists (written by wavog_compare: one pixel, or
three in the zoomed window, per cell) and writes DIR/disagreement_<workload>.png: wavog-clamp
against OctoMap and against the dense grid, whole map and zoomed window side by side, with axes
in metres and the colours' legend. Needs matplotlib (Debian: python3-matplotlib); `make compare`
runs it.
"""

import json
import os
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
from figure_common import DPI, run  # noqa: E402; sets matplotlib's display-less backend first

import matplotlib.image as mpimg  # noqa: E402
import matplotlib.patches as mpatches  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402


def plot_workload(workload, legend, out_dir, out_path):
    pictures = workload["pictures"]
    others = []
    for p in pictures:
        if p["other"] not in others:
            others.append(p["other"])
    fig = plt.figure(figsize=(12, 5.4 * len(others) + 1.0), constrained_layout=True)
    grid = fig.add_gridspec(len(others) + 1, 2, height_ratios=[0.7] + [5.4] * len(others))
    key = fig.add_subplot(grid[0, :])
    key.axis("off")
    key.legend(handles=[mpatches.Patch(facecolor=[c / 255.0 for c in e["rgb"]], edgecolor="0.5",
                                       label=e["meaning"]) for e in legend],
               loc="center", ncol=4, frameon=False)
    for row, other in enumerate(others):
        for col, zoom in enumerate((False, True)):
            match = [p for p in pictures if p["other"] == other and p["zoom"] == zoom]
            if not match:
                continue
            ax = fig.add_subplot(grid[row + 1, col])
            ax.imshow(mpimg.imread(os.path.join(out_dir, match[0]["file"])),
                      extent=match[0]["extent_m"], interpolation="nearest")
            ax.set_title("wavog-clamp vs %s, %s"
                         % (other, "window with the most disagreements" if zoom else "whole map"))
            ax.set_xlabel("x (m)")
            ax.set_ylabel("y (m)")
    fig.suptitle("Where the maps disagree: %s at %.0f cm"
                 % (workload["label"], workload["resolution_m"] * 100))
    fig.savefig(out_path, dpi=DPI)
    plt.close(fig)


def draw(out_dir):
    with open(os.path.join(out_dir, "pictures.json")) as f:
        data = json.load(f)
    written = []
    for workload in data["workloads"]:
        if workload["pictures"]:
            written.append(os.path.join(out_dir, "disagreement_%s.png" % workload["name"]))
            plot_workload(workload, data["legend"], out_dir, written[-1])
    return written


if __name__ == "__main__":
    sys.exit(run(sys.argv, __doc__, draw))
