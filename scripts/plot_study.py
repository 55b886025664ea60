#!/usr/bin/env python3
"""A study's figures across the layers of a build and across the grid values (scanhead_study collect).

usage: plot_study.py SUMMARY_CSV OUT_DIR
       plot_study.py --serve   (import matplotlib now; then read the study folder and the line "images" on stdin:
                                scanhead_study starts it with the cases, so only the drawing is left at the end)

Writes OUT_DIR/summary_layers.png when the study has layered jobs (each figure against the layer, one line per
job and grid combination, the worst layer marked) and OUT_DIR/summary_grid.png when it has a grid (each figure per
combination of grid values, one bar per job and layer group, averaged over layers).
"""
import csv
import os
import sys
from collections import OrderedDict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

FIXED = ["case", "job", "layer", "status", "error", "wall_s", "layer_time_s", "fill_rate_pct",
         "mark_under_10um_pct", "mark_under_20um_pct", "mark_under_30um_pct", "contour_under_10um_pct",
         "contour_under_20um_pct", "contour_under_30um_pct", "hatch_under_10um_pct", "hatch_under_20um_pct",
         "hatch_under_30um_pct", "peak_energy_jmm2", "worst_corner_peak_ratio", "laser_early_samples",
         "laser_late_samples", "dropped_samples"]
# (column, axis label, lower is worse)
FIGURES = [("fill_rate_pct", "fill rate [%]", True),
           ("contour_under_10um_pct", "contour points < 10 µm [%]", True),
           ("mark_under_10um_pct", "marked points < 10 µm [%]", True),
           ("peak_energy_jmm2", "energy peak [J/mm²]", False),
           ("worst_corner_peak_ratio", "worst corner peak / track mean", False),
           ("layer_time_s", "layer time [s]", False)]


def main():
    if sys.argv[1:] == ["--serve"]:
        folder = sys.stdin.readline().strip()
        if not folder or sys.stdin.readline().strip() != "images":
            return  # the study ended without a summary to draw
        plot(os.path.join(folder, "summary.csv"), folder)
    elif len(sys.argv) == 3:
        plot(sys.argv[1], sys.argv[2])
    else:
        sys.exit(__doc__)


def plot(summary_csv, out):
    with open(summary_csv, newline="") as f:
        rows = [r for r in csv.DictReader(f) if r["status"] == "done"]
    if not rows:
        return
    grid_keys = [k for k in rows[0].keys() if k not in FIXED]
    jobs = sorted({r["job"] for r in rows})
    if any(r["layer"] for r in rows) or len(jobs) > 1:
        layers_figure(rows, grid_keys, os.path.join(out, "summary_layers.png"))
    if grid_keys:
        grid_figure(rows, grid_keys, os.path.join(out, "summary_grid.png"))


def label_of(row, keys):
    return ", ".join(f"{k.split('.')[-1]}={row[k]}" for k in keys)


def layers_figure(rows, grid_keys, path):
    """Against the layer of a layered file; a build given as one file per layer: against the file, in name order."""
    by_layer = any(r["layer"] for r in rows)
    jobs = sorted({r["job"] for r in rows})
    series = OrderedDict()
    for r in rows:
        if by_layer and not r["layer"]:
            continue
        r = dict(r, x=int(r["layer"]) if by_layer else jobs.index(r["job"]))
        if by_layer:
            name = r["job"] + (" (" + label_of(r, grid_keys) + ")" if grid_keys else "")
        else:
            name = label_of(r, grid_keys) if grid_keys else "cases"
        series.setdefault(name, []).append(r)
    fig, axes = plt.subplots(3, 2, figsize=(11, 9), sharex=True)
    for ax, (column, label, low_is_worse) in zip(axes.flat, FIGURES):
        drawn = False
        points = []  # (value, x, where) of every point: the worst one is marked
        for name, group in series.items():
            # "" : no such points (a job without contours); a corner ratio of 0: no corner in the job
            group = [r for r in sorted(group, key=lambda r: r["x"])
                     if r[column] != "" and not (column == "worst_corner_peak_ratio" and float(r[column]) == 0)]
            if not group:
                continue
            x = [r["x"] for r in group]
            y = [float(r[column]) for r in group]
            ax.plot(x, y, "o-", ms=4, label=name)
            drawn = True
            points += [(v, xv, f"layer {xv}" if by_layer else r["job"]) for v, xv, r in zip(y, x, group)]
        if points:
            v, xv, where = min(points) if low_is_worse else max(points)
            ax.annotate(f"worst: {where}", (xv, v), textcoords="offset points", xytext=(4, 6), fontsize=8,
                        color="tab:red")
        if not drawn:
            ax.text(0.5, 0.5, "not in these jobs", transform=ax.transAxes, ha="center", va="center", color="gray")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    for ax in axes[-1]:
        ax.set_xlabel("layer (in file order)" if by_layer else "job file (in name order)")
        if not by_layer:
            ax.set_xticks(range(len(jobs)))
            ax.set_xticklabels(jobs, rotation=20, ha="right", fontsize=8)
    axes[0][0].legend(fontsize=7, loc="best")
    fig.suptitle(f"Study: figures across the layers ({len(rows)} cases)")
    fig.tight_layout()
    fig.savefig(path, dpi=100)


def grid_figure(rows, grid_keys, path):
    groups = OrderedDict()
    for r in rows:
        groups.setdefault(label_of(r, grid_keys), []).append(r)
    names = list(groups.keys())
    fig, axes = plt.subplots(3, 2, figsize=(11, 9))
    for ax, (column, label, _) in zip(axes.flat, FIGURES):
        values = [[float(r[column]) for r in groups[n]
                   if r[column] != "" and not (column == "worst_corner_peak_ratio" and float(r[column]) == 0)]
                  for n in names]
        means = [sum(v) / len(v) if v else float("nan") for v in values]
        if all(m != m for m in means):
            ax.text(0.5, 0.5, "not in these jobs", transform=ax.transAxes, ha="center", va="center", color="gray")
            ax.set_ylabel(label)
            ax.set_xticks([])
            continue
        bars = ax.bar(range(len(names)), means, color="tab:blue")
        for b, v in zip(bars, means):
            ax.annotate(f"{v:.4g}", (b.get_x() + b.get_width() / 2, v), ha="center", va="bottom", fontsize=8)
        ax.set_xticks(range(len(names)))
        ax.set_xticklabels(names, rotation=20, ha="right", fontsize=8)
        ax.set_ylabel(label)
        lo, hi = min(m for m in means if m == m), max(m for m in means if m == m)
        pad = 0.15 * (hi - lo) if hi > lo else 0.05 * abs(hi) + 1e-9
        if column.endswith("_pct"):  # shares: zoomed on their spread, the labels inside
            ax.set_ylim(lo - 3 * pad, hi + 2 * pad)
        else:  # quantities: from 0, room above the tallest bar for its label
            ax.set_ylim(0, 1.15 * hi if hi > 0 else 1)
        ax.grid(axis="y", alpha=0.3)
    n_layers = max(len(g) for g in groups.values())
    fig.suptitle(f"Study: figures per grid combination (mean over {n_layers} job/layer case(s) each)")
    fig.tight_layout()
    fig.savefig(path, dpi=100)


if __name__ == "__main__":
    main()
