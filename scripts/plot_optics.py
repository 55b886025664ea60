#!/usr/bin/env python3
"""Plots of the optical chain's assembly defects (SPEC §4, OPT Fig. 5 and 6).

usage: plot_optics.py influence INFLUENCE.yaml OUT.png
       plot_optics.py field FIELD.csv OUT.png [--title TEXT]

influence: the table written by influenceYaml() (include/scanhead/optics/influence_map.hpp): for
  each of the 30 defects alone (1 mm or 1 mrad), the global shift |I(O_p)| and the non-linear part
  max |I - I(O_p)| over the field, positions on the left, orientations on the right, log scale
  (the window tilts are ~1000x smaller than the rest).
field: the CSV written by defectFieldCsv(): arrows from the nominal spot h(theta) along the
  displacement h_defect(theta) - h(theta) over the field, scaled up, coloured by magnitude.
"""
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import yaml  # noqa: E402

LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)

# Values below this [um] (exactly 0 in theory, e.g. the non-linear part of a work-plane x shift)
# are drawn at this floor so that the log scale can show them.
FLOOR_UM = 1e-3


def element_of(label):
    return label.split(".")[0]


def bar_panel(ax, rows, title):
    labels = [r["label"] for r in rows]
    shift = np.array([np.hypot(*r["shift_mm"]) * 1e3 for r in rows])  # um
    nonlinear = np.array([float(r["nonlinear_um"]) for r in rows])
    x = np.arange(len(rows))
    width = 0.4
    for offset, values, colour, name in ((-width / 2, shift, "tab:blue", "global shift |I(O_p)|"),
                                         (width / 2, nonlinear, "tab:orange",
                                          "non-linear part max |I - I(O_p)| over the field")):
        shown = np.maximum(values, FLOOR_UM)
        ax.bar(x + offset, shown, width, color=colour, label=name)
        for xi, v in zip(x + offset, values):
            if v < FLOOR_UM:
                ax.text(xi, FLOOR_UM * 1.3, "0", ha="center", va="bottom", fontsize=7)
    # element groups
    for k in range(1, len(rows)):
        if element_of(labels[k]) != element_of(labels[k - 1]):
            ax.axvline(k - 0.5, color="0.8", lw=0.8)
    ax.set_xticks(x)
    ax.set_xticklabels(labels, rotation=70, ha="right", fontsize=8)
    ax.set_yscale("log")
    ax.set_ylim(FLOOR_UM * 0.7, 1e4)
    ax.set_xlim(-0.7, len(rows) - 0.3)
    ax.grid(True, axis="y", which="major", color="0.9")
    ax.set_title(title, fontsize=10)


def plot_influence(path, out):
    with open(path) as f:
        rows = yaml.load(f, Loader=LOADER)["defects"]
    positions = [r for r in rows if r["label"].split(".")[1] in "xyz"]
    orientations = [r for r in rows if r["label"].split(".")[1] in "abc"]
    fig, axes = plt.subplots(1, 2, figsize=(13, 5.5), gridspec_kw={"width_ratios": [len(positions), len(orientations)]},
                             sharey=True)
    bar_panel(axes[0], positions, "Position defects, 1 mm each")
    bar_panel(axes[1], orientations, "Orientation defects, 1 mrad each")
    axes[0].set_ylabel("spot displacement [µm] (log)")
    axes[1].legend(loc="upper right", fontsize=8)
    fig.suptitle("Influence of each assembly defect alone over the field (OPT Fig. 5); "
                 "bars marked 0 are below %g µm (zero in theory)" % FLOOR_UM, fontsize=10)
    fig.tight_layout()
    fig.savefig(out, dpi=110, bbox_inches="tight")


def plot_field(path, out, title):
    data = np.genfromtxt(path, delimiter=",", names=True)
    x = data["x_m"] * 1e3
    y = data["y_m"] * 1e3
    dx = data["dx_m"] * 1e6  # um
    dy = data["dy_m"] * 1e6
    magnitude = np.hypot(dx, dy)
    n = int(round(np.sqrt(len(x))))
    spacing = (x.max() - x.min()) / max(n - 1, 1)  # mm between grid points
    largest = magnitude.max()
    # arrows magnified by a round factor (1, 2, 5 × 10^k) that draws the largest displacement as
    # at most 0.9 grid spacing
    magnification = 1.0
    if largest > 0:
        limit = 0.9 * spacing * 1e3 / largest  # [mm of plot per mm of displacement]
        exponent = np.floor(np.log10(limit))
        magnification = max(m for m in (1, 2, 5, 10) if m * 10 ** exponent <= limit) * 10 ** exponent
    um_per_mm = 1e3 / magnification
    key_um = float("%.1g" % largest) if largest > 0 else 1.0
    fig, ax = plt.subplots(figsize=(8, 7))
    arrows = ax.quiver(x, y, dx, dy, magnitude, angles="xy", scale_units="xy", scale=um_per_mm, cmap="viridis",
                       width=0.003)
    fig.colorbar(arrows, ax=ax, label="displacement [µm]")
    # a strip below the arrows for the key and the legend
    ax.set_xlim(x.min() - spacing, x.max() + spacing)
    ax.set_ylim(y.min() - 2.5 * spacing, y.max() + spacing)
    ax.quiverkey(arrows, 0.06, 0.035, key_um, "%g µm" % key_um, labelpos="E", coordinates="axes")
    ax.plot(x[magnitude.argmax()], y[magnitude.argmax()], "o", mfc="none", mec="tab:red", ms=10,
            label="max %.1f µm" % largest)
    centre = np.argmin(np.hypot(x, y))
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm] (nominal spot)")
    ax.set_ylabel("y [mm]")
    ax.legend(loc="lower right", fontsize=8)
    ax.set_title("%s\nmax %.1f µm; at the centre (dx, dy) = (%.1f, %.1f) µm\narrows magnified × %g" %
                 (title, largest, dx[centre], dy[centre], magnification), fontsize=10)
    fig.savefig(out, dpi=110, bbox_inches="tight")


def main():
    args = sys.argv[1:]
    title = "Spot displacement over the field (OPT Fig. 6)"
    if "--title" in args:
        k = args.index("--title")
        if k + 1 >= len(args):
            sys.exit(__doc__)
        title = args[k + 1]
        del args[k:k + 2]
    if len(args) != 3 or args[0] not in ("influence", "field"):
        sys.exit(__doc__)
    if args[0] == "influence":
        plot_influence(args[1], args[2])
    else:
        plot_field(args[1], args[2], title)


if __name__ == "__main__":
    main()
