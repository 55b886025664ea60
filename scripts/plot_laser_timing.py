#!/usr/bin/env python3
"""Where the laser comes on after a jump, for several results folders (e.g. two laser-on delays).

usage: plot_laser_timing.py OUT.png LABEL=RESULTS_DIR [LABEL=RESULTS_DIR ...]

For each folder (written by scanhead_run or the energy node), the first laser-on sample after the
second laser-off gap of trace.csv (the jump from the inner to the outer contour on the THESIS
square job) is found; the actual spot path around it is drawn in grey where the laser is off and
in red where it is on, with the commanded marks in black and the early/late counts of
metrics.yaml in the title. Shows what too short a laser-on delay burns during the jump's settling.
"""
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, __file__.rsplit("/", 1)[0])
from plot_results import load, mark_segments  # noqa: E402


def laser_starts(power):
    on = power > 0
    return np.flatnonzero(on[1:] & ~on[:-1]) + 1


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    out = sys.argv[1]
    runs = [arg.split("=", 1) for arg in sys.argv[2:]]
    fig, axes = plt.subplots(1, len(runs), figsize=(6 * len(runs), 5.5), squeeze=False)
    for ax, (label, folder) in zip(axes[0], runs):
        trace, job, metrics, _ = load(folder)
        starts = laser_starts(trace["power_w"])
        k = starts[min(1, len(starts) - 1)]
        window = slice(max(0, k - 60), k + 60)
        x = trace["actual_x_m"][window] * 1e3
        y = trace["actual_y_m"][window] * 1e3
        on = trace["power_w"][window] > 0
        for a, b in zip(*mark_segments(job)):
            ax.plot([a[0] * 1e3, b[0] * 1e3], [a[1] * 1e3, b[1] * 1e3], "k-", lw=0.8)
        ax.plot(x, y, "-", color="0.8", lw=0.8)
        ax.plot(x[~on], y[~on], "o", color="0.5", ms=3, label="laser off")
        ax.plot(x[on], y[on], "o", color="tab:red", ms=3, label="laser on")
        cx, cy = trace["actual_x_m"][k] * 1e3, trace["actual_y_m"][k] * 1e3
        half = 0.2  # mm around the sample where the laser comes on
        ax.set_xlim(cx - half, cx + half)
        ax.set_ylim(cy - half, cy + half)
        ax.set_aspect("equal")
        ax.set_xlabel("x [mm]")
        ax.set_ylabel("y [mm]")
        ax.set_title(f"{label}: {metrics['laser_early_samples']} early samples in the job\n"
                     "(laser on > 30 um from its mark, energy.laser_path_tolerance_m)", fontsize=9)
        ax.legend(loc="best", fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=110, bbox_inches="tight")


if __name__ == "__main__":
    main()
