#!/usr/bin/env python3
"""Plots of a scanhead results folder: energy map, speed and contour error along the path.

usage: plot_results.py RESULTS_DIR

Reads trace.csv, job.yaml, metrics.yaml, energy_map.yaml and energy_map_16bit.png written by
scanhead_run or the energy_accumulator node, and writes energy_map_plot.png, speed.png,
contour_error.png, corner_zoom.png and quality.png (contour-error distributions by definition and
kind, angle-error histograms, speed on the marks) next to them.
"""
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import yaml  # noqa: E402
from PIL import Image  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from quality_plots import quality_figure  # noqa: E402


LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


def load_metrics_head(path):
    """metrics.yaml up to its first corner: a whole layer has ~1e5 corners the plots do not need."""
    lines = []
    corners = 0
    with open(path) as f:
        for line in f:
            if line.startswith("  - polyline:"):
                corners += 1
                if corners > 1:
                    break
            lines.append(line)
    return yaml.load("".join(lines), Loader=LOADER)


def load(folder):
    trace = np.genfromtxt(os.path.join(folder, "trace.csv"), delimiter=",", names=True)
    with open(os.path.join(folder, "job.yaml")) as f:
        job = yaml.load(f, Loader=LOADER)
    metrics = load_metrics_head(os.path.join(folder, "metrics.yaml"))
    with open(os.path.join(folder, "energy_map.yaml")) as f:
        energy = yaml.load(f, Loader=LOADER)
    return trace, job, metrics, energy


def polylines_with_gaps(job, kind=None):
    """The polylines' points (all, or those of type `kind`) in mm as one array, NaN rows between
    them, so a whole layer is one plot call."""
    parts = []
    for line in job["polylines"]:
        if kind is None or line["type"] == kind:
            parts.append(np.asarray(line["points"], dtype=float) * 1e3)
            parts.append(np.full((1, 2), np.nan))
    return np.vstack(parts) if parts else np.zeros((0, 2))


def mark_segments(job):
    """Commanded MARK segments as (start, end) arrays in m."""
    starts, ends = [], []
    for line in job["polylines"]:
        if line["type"] != "mark":
            continue
        pts = np.asarray(line["points"], dtype=float)
        starts.append(pts[:-1])
        ends.append(pts[1:])
    if not starts:
        return np.zeros((0, 2)), np.zeros((0, 2))
    return np.vstack(starts), np.vstack(ends)


def distance_to_path(points, starts, ends, block=256, reach=1e-3):
    """Distance from each point to the nearest commanded segment.

    Points go in blocks of consecutive trace rows (a small area); each block is compared with the
    segments whose box comes within `reach` of the block's box only (all segments if none does),
    so a 300-square layer takes seconds, not minutes. A distance above `reach` may then be an
    over-estimate, which the plots do not need.
    """
    if len(starts) == 0:
        return np.full(len(points), np.nan)
    out = np.empty(len(points))
    lo_seg = np.minimum(starts, ends)
    hi_seg = np.maximum(starts, ends)
    for i in range(0, len(points), block):
        p = points[i:i + block]
        lo = np.nanmin(p, axis=0) - reach
        hi = np.nanmax(p, axis=0) + reach
        near = np.all((hi_seg >= lo) & (lo_seg <= hi), axis=1)
        if not near.any():
            near[:] = True
        a, b = starts[near], ends[near]
        d = b - a
        length2 = np.maximum((d * d).sum(axis=1), 1e-300)
        q = p[:, None, :]
        t = np.clip(((q - a) * d).sum(axis=2) / length2, 0.0, 1.0)
        nearest = a + t[..., None] * d
        out[i:i + block] = np.sqrt(((q - nearest) ** 2).sum(axis=2)).min(axis=1)
    return out


def plot_energy(folder, job, energy):
    image = np.asarray(Image.open(os.path.join(folder, "energy_map_16bit.png")))
    step = max(1, int(np.ceil(np.sqrt(image.size / 4e6))))  # a figure shows no more than ~4 Mpixels
    image = image[::step, ::step].astype(float)
    density = image / 65535.0 * energy["scale_max_jpm2"] * 1e-6  # J/mm²
    x0, y0 = energy["origin_m"]
    pixel = energy["pixel_m"]
    extent = [x0 * 1e3, (x0 + pixel * energy["width"]) * 1e3, y0 * 1e3, (y0 + pixel * energy["height"]) * 1e3]
    fig, ax = plt.subplots(figsize=(8, 6))
    shown = ax.imshow(density, origin="upper", extent=extent, cmap="inferno")  # row 0 = top (+y up)
    for kind, style in (("mark", "-"), ("jump", "--")):
        pts = polylines_with_gaps(job, kind)
        ax.plot(pts[:, 0], pts[:, 1], style, color="cyan", lw=0.6)
    fig.colorbar(shown, ax=ax, label="energy density [J/mm²]")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    ax.set_title("Deposited energy (commanded path in cyan)")
    fig.savefig(os.path.join(folder, "energy_map_plot.png"), dpi=120, bbox_inches="tight")
    plt.close(fig)


def plot_speed(folder, trace, job):
    fig, ax = plt.subplots(figsize=(9, 4))
    t = trace["t_s"] * 1e3
    ax.plot(t, trace["setpoint_speed_mps"] * 1e3, label="setpoint (Q_filt2)")
    ax.plot(t, trace["actual_speed_mps"] * 1e3, label="actual (after servo)")
    for speed in sorted({line["speed"] for line in job["polylines"] if line["type"] == "mark"}):
        ax.axhline(speed * 1e3, color="grey", ls=":", lw=0.8)
    ax.set_xlabel("time [ms]")
    ax.set_ylabel("spot speed [mm/s]")
    ax.legend()
    ax.grid(alpha=0.3)
    fig.savefig(os.path.join(folder, "speed.png"), dpi=120, bbox_inches="tight")
    plt.close(fig)


def plot_contour_error(folder, trace, job):
    starts, ends = mark_segments(job)
    on = trace["power_w"] > 0
    fig, ax = plt.subplots(figsize=(9, 4))
    t = trace["t_s"] * 1e3
    for name, label in (("setpoint", "setpoint"), ("actual", "actual")):
        pts = np.column_stack([trace[name + "_x_m"], trace[name + "_y_m"]])
        err = distance_to_path(pts, starts, ends) * 1e6
        ax.plot(t[on], err[on], ".", ms=2, label=label + " (laser on)")
    ax.set_xlabel("time [ms]")
    ax.set_ylabel("distance to the commanded path [µm]")
    ax.legend()
    ax.grid(alpha=0.3)
    fig.savefig(os.path.join(folder, "contour_error.png"), dpi=120, bbox_inches="tight")
    plt.close(fig)


def plot_corner(folder, trace, job, metrics):
    corners = metrics.get("corners") or []
    if not corners:
        return
    c = np.asarray(corners[0]["point_m"]) * 1e3
    half = max(0.15, 3 * corners[0]["theory"]["max_contour_error_m"] * 1e3)
    fig, ax = plt.subplots(figsize=(6, 6))
    pts = polylines_with_gaps(job)
    ax.plot(pts[:, 0], pts[:, 1], "k-", lw=1, label="commanded")
    ax.plot(trace["setpoint_x_m"] * 1e3, trace["setpoint_y_m"] * 1e3, label="setpoint (Q_filt2)")
    ax.plot(trace["actual_x_m"] * 1e3, trace["actual_y_m"] * 1e3, label="actual")
    ax.set_xlim(c[0] - half, c[0] + half)
    ax.set_ylim(c[1] - half, c[1] + half)
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    ax.set_title("First corner: %.2f° at %.0f mm/s" % (corners[0]["angle_deg"], corners[0]["programmed_speed_mps"] * 1e3))
    handles, labels = ax.get_legend_handles_labels()
    unique = dict(zip(labels, handles))
    ax.legend(unique.values(), unique.keys())
    fig.savefig(os.path.join(folder, "corner_zoom.png"), dpi=120, bbox_inches="tight")
    plt.close(fig)


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    folder = sys.argv[1]
    trace, job, metrics, energy = load(folder)
    plot_energy(folder, job, energy)
    plot_speed(folder, trace, job)
    plot_contour_error(folder, trace, job)
    plot_corner(folder, trace, job, metrics)
    fig = quality_figure(plt, [(metrics.get("job", "run"), metrics)])
    fig.savefig(os.path.join(folder, "quality.png"), dpi=110, bbox_inches="tight")
    plt.close(fig)


if __name__ == "__main__":
    main()
