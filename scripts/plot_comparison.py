#!/usr/bin/env python3
"""Two runs side by side: contour-error distributions, angle errors and speed (scanhead_compare --out).

usage: plot_comparison.py METRICS_A METRICS_B LABEL_A LABEL_B OUT_PNG
"""
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from plot_results import load_metrics_head  # noqa: E402
from quality_plots import quality_figure  # noqa: E402


def main():
    if len(sys.argv) != 6:
        sys.exit(__doc__)
    a, b, label_a, label_b, out = sys.argv[1:]
    fig = quality_figure(plt, [(label_a, load_metrics_head(a)), (label_b, load_metrics_head(b))])
    fig.savefig(out, dpi=110, bbox_inches="tight")


if __name__ == "__main__":
    main()
