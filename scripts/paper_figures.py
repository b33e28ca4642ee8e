#!/usr/bin/python3
"""Draws the paper's Fig. 1.2, 1.3, 1.4 and 1.6 from the rasters wavog_paper exports.

Usage: paper_figures.py DIR   (DIR holds stats.json and the *.f32 / *.known.u8 / *.json rasters;
the figures fig_1_2.png, fig_1_3.png, fig_1_4.png and fig_1_6.png are written there).
Colour code as in the paper's captions: the brighter, the more occupied; each panel's scale runs
from its map's minimum to its maximum log-odds over the observed cells, shown by a colour bar in
log-odds. Never-observed cells hold the map's prior (that is the map's value there) and are
hatched in pale blue so they are not mistaken for observed ones. Axes in metres (map frame).
"""
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.colors import ListedColormap  # noqa: E402

PANEL = "abcdefgh"
UNKNOWN_RGBA = (0.80, 0.88, 0.97, 1.0)


def num(v, digits=1):
    """v rounded for a label, without a minus sign on zero (-1e-7 after the Haar round trip)."""
    return f"{round(v, digits) + 0.0:.{digits}f}"


def load_raster(directory, side):
    w, h = side["width"], side["height"]
    lo = np.fromfile(os.path.join(directory, side["log_odds_file"]), dtype="<f4").reshape(h, w)
    known = np.fromfile(os.path.join(directory, side["known_file"]), dtype=np.uint8).reshape(h, w)
    return lo, known.astype(bool)


def extent(side):
    x0, y0, cs = side["origin_x_m"], side["origin_y_m"], side["cell_size_m"]
    return [x0, x0 + side["width"] * cs, y0, y0 + side["height"] * cs]


def crop(lo, known, side, window):
    """The part of a raster inside window = (x0, y0, x1, y1) metres, and its extent."""
    x0, y0, cs = side["origin_x_m"], side["origin_y_m"], side["cell_size_m"]
    c0 = max(0, int(np.floor((window[0] - x0) / cs)))
    c1 = min(side["width"], int(np.ceil((window[2] - x0) / cs)))
    r0 = max(0, int(np.floor((window[1] - y0) / cs)))
    r1 = min(side["height"], int(np.ceil((window[3] - y0) / cs)))
    ext = [x0 + c0 * cs, x0 + c1 * cs, y0 + r0 * cs, y0 + r1 * cs]
    return lo[r0:r1, c0:c1], known[r0:r1, c0:c1], ext


def draw_map(fig, ax, lo, known, ext, title, vmin=None, vmax=None, mark_unknown=True):
    """One log-odds map: grey scale from the observed minimum to the maximum, colour bar."""
    if known.any():
        vmin = float(lo[known].min()) if vmin is None else vmin
        vmax = float(lo[known].max()) if vmax is None else vmax
    if vmin is None or vmax is None or vmax <= vmin:
        vmin, vmax = -1.0, 1.0
    im = ax.imshow(lo, origin="lower", extent=ext, cmap="gray", vmin=vmin, vmax=vmax,
                   interpolation="nearest")
    if mark_unknown:
        overlay = np.zeros(lo.shape + (4,))
        overlay[~known] = UNKNOWN_RGBA
        ax.imshow(overlay, origin="lower", extent=ext, interpolation="nearest")
    ax.set_title(title, fontsize=10)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    bar = fig.colorbar(im, ax=ax, fraction=0.046, pad=0.02)
    bar.set_label("log-odds  ln(P(occ) / P(emp))")
    return im


def unknown_legend(fig):
    patch = matplotlib.patches.Patch(color=UNKNOWN_RGBA, label="never observed (the prior)")
    fig.legend(handles=[patch], loc="upper center", bbox_to_anchor=(0.5, 0.0), fontsize=10,
               frameon=True)


def zoom_box(ax, window):
    ax.add_patch(matplotlib.patches.Rectangle((window[0], window[1]), window[2] - window[0],
                                              window[3] - window[1], fill=False,
                                              edgecolor="tab:red", linewidth=1.2))


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    d = sys.argv[1]
    with open(os.path.join(d, "stats.json")) as f:
        stats = json.load(f)
    runs = {r["run"]: r for r in stats["runs"]}
    zoom = stats["zoom_m"]
    four = [("none", "no policy"), ("max", "max policy"), ("clamp", "clamping policy"),
            ("forget", "exponential forgetting policy")]
    log = os.path.basename(stats["log"])

    # Fig. 1.2: the four policies, whole map.
    side0 = runs["none"]["rasters"][0]
    w_m = side0["width"] * side0["cell_size_m"]
    h_m = side0["height"] * side0["cell_size_m"]
    cols, rows, panel_w = 2, 2, 9.0
    fig, axes = plt.subplots(rows, cols, figsize=(cols * panel_w, rows * panel_w * h_m / w_m + 1.6),
                             squeeze=False, constrained_layout=True)
    for i, (name, label) in enumerate(four):
        side = runs[name]["rasters"][0]
        lo, known = load_raster(d, side)
        ax = axes[i // cols][i % cols]
        draw_map(fig, ax, lo, known, extent(side),
                 f"({PANEL[i]}) {label}: log-odds {num(side['min_log_odds'])} .. "
                 f"{num(side['max_log_odds'])}")
        zoom_box(ax, zoom)
    fig.suptitle(f"Fig. 1.2: log-odds maps of {log} ({stats['scans']} scans, "
                 f"{side0['cell_size_m'] * 100:.0f} cm cells)\nbrighter = more occupied; each "
                 "scale from its map's min to max log-odds; red box: the zoom of Fig. 1.3",
                 fontsize=12)
    unknown_legend(fig)
    fig.savefig(os.path.join(d, "fig_1_2.png"), dpi=110, bbox_inches="tight")
    plt.close(fig)

    # Fig. 1.3: the same zoom for the four.
    fig, axes = plt.subplots(2, 2, figsize=(12, 12 * (zoom[3] - zoom[1]) / (zoom[2] - zoom[0]) + 1.5),
                             squeeze=False, constrained_layout=True)
    for i, (name, label) in enumerate(four):
        side = runs[name]["rasters"][0]
        lo, known = load_raster(d, side)
        zl, zk, ext = crop(lo, known, side, zoom)
        r = runs[name]
        draw_map(fig, axes[i // 2][i % 2], zl, zk, ext,
                 f"({PANEL[i]}) {label}: wall width {r['wall_width_mean_cells']:.2f} cells "
                 "(whole map)")
    fig.suptitle(f"Fig. 1.3: zoom x {zoom[0]:g}..{zoom[2]:g} m, y {zoom[1]:g}..{zoom[3]:g} m; "
                 "each scale from the zoom's min to max log-odds", fontsize=11)
    unknown_legend(fig)
    fig.savefig(os.path.join(d, "fig_1_3.png"), dpi=110, bbox_inches="tight")
    plt.close(fig)

    # Fig. 1.4: forgetting with the empty-bound prior, whole map and zoom.
    r = runs["forget_empty_bound"]
    side = r["rasters"][0]
    lo, known = load_raster(d, side)
    zl, zk, zext = crop(lo, known, side, zoom)
    aspects = [w_m / h_m, (zoom[2] - zoom[0]) / (zoom[3] - zoom[1])]
    fig, axes = plt.subplots(1, 2, figsize=(18, 18 / sum(aspects) + 1.6), constrained_layout=True,
                             gridspec_kw={"width_ratios": aspects})
    draw_map(fig, axes[0], lo, known, extent(side),
             f"(a) entire map: log-odds {side['min_log_odds']:.2f} .. {side['max_log_odds']:.2f}",
             mark_unknown=False)
    zoom_box(axes[0], zoom)
    draw_map(fig, axes[1], zl, zk, zext, "(b) zoom (red box in (a))", mark_unknown=False)
    fig.suptitle("Fig. 1.4: exponential forgetting, map initialised to the empty bound "
                 f"(prior {side['prior_log_odds']:g}: never-observed cells look empty, as in "
                 f"the paper)\n{r['bytes_per_observed_cell']:.2f} bytes per observed cell, "
                 f"{r['nodes']} nodes (unknown prior: "
                 f"{runs['forget']['bytes_per_observed_cell']:.2f}, {runs['forget']['nodes']})",
                 fontsize=12)
    fig.savefig(os.path.join(d, "fig_1_4.png"), dpi=110, bbox_inches="tight")
    plt.close(fig)

    # Fig. 1.6: scales 0, 2, 3, 4 of the forgetting map.
    sides = runs["forget"]["rasters"]
    fig, axes = plt.subplots(2, 2, figsize=(14, 14 * h_m / w_m + 2.0), squeeze=False,
                             constrained_layout=True)
    base = sides[0]["known_cells"]
    for i, side in enumerate(sides):
        lo, known = load_raster(d, side)
        cm = side["cell_size_m"] * 100
        ratio = base / side["known_cells"] if side["known_cells"] else float("nan")
        prev = f", 1 : {sides[i - 1]['known_cells'] / side['known_cells']:.1f} vs scale " \
               f"{sides[i - 1]['scale']}" if i > 1 else ""
        vs0 = f" (1 : {ratio:.1f} vs scale 0{prev})" if i else ""
        draw_map(fig, axes[i // 2][i % 2], lo, known, extent(side),
                 f"({PANEL[i]}) scale {side['scale']}, cells {cm:.0f} cm x {cm:.0f} cm\n"
                 f"{side['known_cells']:,} observed of {side['cells']:,} cells{vs0}")
    fig.suptitle("Fig. 1.6: scales 0, 2, 3, 4 of the forgetting map of "
                 f"{log}\n(Haar averages: mean log-odds of the 4^s finest cells under a cell, unobserved "
                 "ones at the prior 0, hence the paler rim; observed if any of them is)",
                 fontsize=12)
    unknown_legend(fig)
    fig.savefig(os.path.join(d, "fig_1_6.png"), dpi=110, bbox_inches="tight")
    plt.close(fig)
    print(f"paper_figures: wrote {d}/fig_1_2.png, fig_1_3.png, fig_1_4.png, fig_1_6.png")


if __name__ == "__main__":
    main()
