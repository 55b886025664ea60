#!/usr/bin/env python3
"""Wall time per stage against job length, from `scanhead_benchmark --scaling CSV` (log-log).

usage: plot_scaling.py CSV OUT_PNG

Lines of slope 1 mean a cost linear in the job length; the flat start of the curves is the fixed
cost of a job (planning, map allocation). The dotted lines are real time and 60x real time.
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

STAGES = [
    ("nc_s", "NC"),
    ("servo_s", "servo"),
    ("optics_s", "optics"),
    ("energy_s", "energy (map + metrics)"),
    ("setup_s", "setup (plan, allocation)"),
    ("batch_chain_s", "whole chain (batch, pipelined)"),
]


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    with open(sys.argv[1]) as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(sys.argv[1] + ": no rows")
    machine = [float(r["machine_s"]) for r in rows]
    fig, ax = plt.subplots(figsize=(7.5, 5))
    for key, label in STAGES:
        style = dict(lw=2.5, color="black") if key == "batch_chain_s" else dict(lw=1.4)
        ax.loglog(machine, [max(float(r[key]), 1e-7) for r in rows], "o-", ms=3, label=label, **style)
    span = [min(machine), max(machine)]
    ax.loglog(span, span, ":", color="grey")
    ax.loglog(span, [m / 60 for m in span], ":", color="tab:red")
    ax.text(span[1], span[1], "real time ", ha="right", va="bottom", color="grey", fontsize=8)
    ax.text(span[1], span[1] / 60, "60x real time ", ha="right", va="bottom", color="tab:red", fontsize=8)
    ax.set_xlabel("job length (machine time) [s]")
    ax.set_ylabel("wall time [s]")
    ax.set_title("scanhead_benchmark --scaling: square hatches at 1 m/s")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8, loc="upper left")
    fig.savefig(sys.argv[2], dpi=110, bbox_inches="tight")


if __name__ == "__main__":
    main()
