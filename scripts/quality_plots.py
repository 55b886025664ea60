"""Layer-quality figures shared by plot_results.py (one run) and plot_comparison.py (two runs):
contour-error distributions (THESIS Fig. 2.74), per-axis angle-error histograms, mark speed ratio."""
import numpy as np

KINDS = ("contour", "hatch", "jump")


def contour_counts(metrics, definition, kind):
    """Counts per 1 um bin (0..100 um, then overflow) of one definition and kind, or None."""
    block = (metrics.get("contour_error") or {}).get(definition)
    if not block:
        return None
    counts = np.asarray(block[kind]["counts_1um"], dtype=float)
    return counts if counts.sum() > 0 else None


def plot_contour_distributions(ax, runs, definition):
    """Share of points under each error, per kind, for each (label, metrics) run."""
    styles = ("-", "--")
    for (label, metrics), style in zip(runs, styles):
        for kind, colour in zip(KINDS, ("tab:blue", "tab:green", "tab:grey")):
            counts = contour_counts(metrics, definition, kind)
            if counts is None:
                continue
            edges = np.arange(1, len(counts) + 1)  # upper edges [um]; the last bin is the overflow
            share = 100.0 * np.cumsum(counts) / counts.sum()
            ax.step(edges[:-1], share[:-1], where="post", color=colour, linestyle=style, label=f"{label}: {kind}")
    for limit in (10, 20, 30):
        ax.axvline(limit, color="k", lw=0.5, alpha=0.4)
    ax.set_xlim(0, 100)
    ax.set_xlabel("contour error [um]")
    ax.set_ylabel("points under it [%]")
    ax.set_title("contour error, " + definition.replace("_", " "))
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="lower right")  # a fixed place: "best" costs a search over the data


def plot_histogram(ax, runs, path, xlabel, title):
    """A metrics.yaml histogram block (edges, counts) for each run, zoomed on the occupied bins."""
    lo_hi = [np.inf, -np.inf]
    for (label, metrics), colour in zip(runs, ("tab:red", "tab:blue")):
        block = metrics
        for key in path:
            block = (block or {}).get(key)
        if not block or not block.get("count"):
            continue
        edges = np.asarray(block["edges"], dtype=float)
        counts = np.asarray(block["counts"], dtype=float)
        occupied = np.nonzero(counts)[0]
        if occupied.size:
            lo_hi = [min(lo_hi[0], edges[occupied[0]]), max(lo_hi[1], edges[occupied[-1] + 1])]
        ax.stairs(100.0 * counts / max(block["count"], 1), edges, color=colour, label=f"{label} "
                  f"(under {block['underflow']}, over {block['overflow']})")
    if lo_hi[0] < lo_hi[1]:
        pad = 0.05 * (lo_hi[1] - lo_hi[0])
        ax.set_xlim(lo_hi[0] - pad, lo_hi[1] + pad)
    ax.set_xlabel(xlabel)
    ax.set_ylabel("samples [%]")
    ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="upper right")


def quality_figure(plt, runs):
    """The 2 x 3 panel figure: contour errors by definition, angle errors x/y, speed ratio."""
    fig, axes = plt.subplots(2, 3, figsize=(15, 8.5))
    plot_contour_distributions(axes[0][0], runs, "same_instant")
    plot_contour_distributions(axes[0][1], runs, "nearest_path")
    plot_histogram(axes[0][2], runs, ("speed_profile", "ratio"), "actual / programmed speed", "speed on the marks")
    plot_histogram(axes[1][0], runs, ("angle_error", "x"), "Q_filt2 - Q_exp [urad]", "angle error, galvo x")
    plot_histogram(axes[1][1], runs, ("angle_error", "y"), "Q_filt2 - Q_exp [urad]", "angle error, galvo y")
    ax = axes[1][2]
    ax.axis("off")
    lines = []
    for label, m in runs:
        q = m.get("contour_error", {}).get("same_instant", {})
        lines.append(f"{label}")
        fill = m.get("fill_rate")
        lines.append(f"  layer time {m.get('layer_time_s', float('nan')):.4f} s")
        lines.append(f"  fill rate {100.0 * fill:.2f} %" if isinstance(fill, (int, float)) else "  fill rate -")
        contour = q.get("contour", {})
        if contour.get("points"):
            lines.append("  contours < 10/20/30 um: " + ", ".join(
                f"{100.0 * contour[f'share_under_{u}um']:.2f} %" for u in (10, 20, 30)))
        lines.append(f"  peak {m.get('peak_energy_density_jpm2', 0) * 1e-6:.3g} J/mm^2")
    ax.text(0.0, 1.0, "\n".join(lines), va="top", family="monospace", fontsize=9)
    # Fixed margins, not tight_layout(): that draws the whole figure once more to measure it.
    fig.subplots_adjust(left=0.05, right=0.98, bottom=0.07, top=0.95, wspace=0.25, hspace=0.32)
    return fig
