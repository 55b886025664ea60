#!/usr/bin/env python3
"""Plots of a scanhead results folder: energy map, speed and contour error along the path.

usage: plot_results.py [--plots all|summary] RESULTS_DIR
       plot_results.py [--plots all|summary] --serve

Reads trace.csv, job.yaml, metrics.yaml, energy_map.yaml and energy_map.tiff (or
energy_map_16bit.png) written by scanhead_run or the energy_accumulator node, and writes
energy_map_plot.png, speed.png, contour_error.png, corner_zoom.png and quality.png
(contour-error distributions by definition and kind, angle-error histograms, speed on the marks)
next to them; --plots summary writes energy_map_plot.png and quality.png only.

--serve: import matplotlib now, then wait for one folder path on stdin (nothing if stdin closes
first) and draw what needs no image, then for the line "images" (the energy images are written)
and draw the energy map. scanhead_run starts it so at the beginning of a run, so the imports
overlap the chain and the drawing overlaps the writing of the images.

Every figure is drawn from bounded data (the trace holds at most 20000 rows, the energy map is
read as block maxima of at most 1000 pixels a side, the commanded path is drawn only up to 20000
points, the contour error for at most 5000 points) so the plots cost about the same whatever the
job; the figures are drawn in forked processes when two cores are available.

Exit status: 0 when every plot is written, 28 (ENOSPC) when the disk (or a quota) is full, so that
the caller can say so (the partial PNG is removed by the writer), 1 on any other failure.
"""
import errno
import io
import os
import re
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import yaml  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from quality_plots import quality_figure  # noqa: E402


LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
PREVIEW_SIDE = 1000  # px: the energy plot shows block maxima of at most this many pixels a side
MAX_PATH_POINTS = 20000  # commanded points drawn over the energy map at most
FAST_PNG = {"compress_level": 1}  # zlib level 1: a third of the encoding time for ~20 % more bytes
SUMMARY = ("energy", "quality")
ALL = ("energy", "quality", "speed", "contour_error", "corner")


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


class Job:
    """The commanded polylines as flat arrays: points (N, 2) [m], polyline k's points are
    points[start[k]:start[k + 1]]; is_mark, contour (role) and speed [m/s] per polyline."""

    def __init__(self, points, counts, is_mark, contour, speed):
        self.points = np.asarray(points, dtype=float).reshape(-1, 2)
        self.start = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
        self.is_mark = np.asarray(is_mark, dtype=bool)
        self.contour = np.asarray(contour, dtype=bool)
        self.speed = np.asarray(speed, dtype=float)

    def select(self, mask):
        """Points of the polylines in `mask` and their point counts."""
        counts = np.diff(self.start)
        keep = np.repeat(mask, counts)
        return self.points[keep], counts[mask]

    def with_gaps(self, mask=None):
        """The selected polylines' points in mm as one array, NaN rows between them, so a whole
        layer is one plot call."""
        if mask is None:
            mask = np.ones(len(self.is_mark), dtype=bool)
        pts, counts = self.select(mask)
        if len(counts) == 0:
            return np.zeros((0, 2))
        return np.insert(pts * 1e3, np.cumsum(counts), np.nan, axis=0)

    def mark_segments(self):
        """Commanded MARK segments as (start, end) arrays in m."""
        pts, counts = self.select(self.is_mark)
        if len(pts) == 0:
            return np.zeros((0, 2)), np.zeros((0, 2))
        first = np.ones(len(pts), dtype=bool)  # a point that starts a segment: not a polyline's last
        first[np.cumsum(counts) - 1] = False
        return pts[first], pts[np.flatnonzero(first) + 1]


# The layout scanJobToYaml writes; any other job.yaml goes through the YAML parser.
POLYLINE = re.compile(r"^  - type: (mark|jump)\n(?:    role: (\w+)\n)?    speed: (\S+)\n    power: \S+\n"
                      r"(?:    dwell: \S+\n)?    points: \[(.*)\]$", re.M)


def load_job(path):
    with open(path) as f:
        text = f.read()
    found = POLYLINE.findall(text)
    if len(found) == text.count("\n  - ") and all(p for *_, p in found):
        counts = [p.count("[") for *_, p in found]
        flat = ",".join(p for *_, p in found).replace("[", "").replace("]", "")
        points = np.array(flat.split(","), dtype=float) if flat else np.zeros(0)
        return Job(points, counts, [t == "mark" for t, *_ in found], [r == "contour" for _, r, *_ in found],
                   [float(s) for _, _, s, _ in found])
    lines = (yaml.load(text, Loader=LOADER) or {}).get("polylines") or []
    return Job(np.concatenate([np.asarray(line["points"], dtype=float).ravel() for line in lines] or [[]]),
               [len(line["points"]) for line in lines], [line["type"] == "mark" for line in lines],
               [line.get("role") == "contour" for line in lines], [line["speed"] for line in lines])


def load(folder):
    """trace.csv as columns, job.yaml and the head of metrics.yaml (energy_map.yaml is read with the
    images: a served run gets the folder before the images are written)."""
    trace = np.loadtxt(os.path.join(folder, "trace.csv"), delimiter=",", skiprows=1, ndmin=2)
    with open(os.path.join(folder, "trace.csv")) as f:
        names = f.readline().strip().split(",")
    trace = {name: trace[:, i] for i, name in enumerate(names)}
    job = load_job(os.path.join(folder, "job.yaml"))
    metrics = load_metrics_head(os.path.join(folder, "metrics.yaml"))
    return trace, job, metrics


def block_max(image, step):
    """Maxima of step x step blocks (the last row and column of blocks may be smaller)."""
    if step <= 1:
        return np.asarray(image, dtype=float)
    rows = np.maximum.reduceat(image, np.arange(0, image.shape[0], step), axis=0)
    return np.maximum.reduceat(rows, np.arange(0, image.shape[1], step), axis=1).astype(float)


def energy_preview(folder, energy):
    """The energy map [J/mm²], row 0 = top, as block maxima of at most PREVIEW_SIDE pixels a side:
    read from the float TIFF (its pixels are the file's last width x height x 4 bytes), else from
    the 16-bit PNG."""
    width, height = energy["width"], energy["height"]
    step = max(1, -(-max(width, height) // PREVIEW_SIDE))
    tiff = os.path.join(folder, "energy_map.tiff")
    if os.path.exists(tiff) and os.path.getsize(tiff) > 4 * width * height:
        pixels = np.memmap(tiff, dtype="<f4", mode="r", offset=os.path.getsize(tiff) - 4 * width * height,
                           shape=(height, width))
        return block_max(pixels, step) * 1e-6
    from PIL import Image
    image = np.asarray(Image.open(os.path.join(folder, "energy_map_16bit.png")))
    return block_max(image, step) / 65535.0 * energy["scale_max_jpm2"] * 1e-6


def new_figure(size, left=0.1, right=0.95, bottom=0.12, top=0.9):
    """A figure with fixed margins: one draw when saved (bbox_inches="tight" draws twice)."""
    fig, ax = plt.subplots(figsize=size)
    fig.subplots_adjust(left=left, right=right, bottom=bottom, top=top)
    return fig, ax


def plot_energy(folder, job):
    with open(os.path.join(folder, "energy_map.yaml")) as f:
        energy = yaml.load(f, Loader=LOADER)
    density = energy_preview(folder, energy)
    x0, y0 = energy["origin_m"]
    pixel = energy["pixel_m"]
    extent = [x0 * 1e3, (x0 + pixel * energy["width"]) * 1e3, y0 * 1e3, (y0 + pixel * energy["height"]) * 1e3]
    fig, ax = new_figure((8, 6), left=0.1, right=0.98, bottom=0.09, top=0.94)
    shown = ax.imshow(density, origin="upper", extent=extent, cmap="inferno", interpolation="nearest")
    # The commanded path over the map only where it does not hide the energy: everything, else the contours
    # only, else nothing (a hatched part: its lines a few pixels apart would paint the map cyan).
    axis_px = 0.8 * 8 * 120  # the map's width on the figure [px]
    mm_per_px = max(extent[1] - extent[0], extent[3] - extent[2]) / axis_px

    def hides(mask):
        """Drawn at lw 0.6 (1 px), the selected polylines would cover more than 1/8 of the map."""
        pts, counts = job.select(mask)
        if len(pts) < 2:
            return False
        steps = np.linalg.norm(np.diff(pts, axis=0), axis=1) * 1e3
        steps[np.cumsum(counts)[:-1] - 1] = 0.0  # no segment between two polylines
        area = (extent[1] - extent[0]) * (extent[3] - extent[2])
        return steps.sum() * mm_per_px > area / 8.0 or len(pts) > MAX_PATH_POINTS

    title = "Deposited energy (commanded path in cyan)"
    if hides(np.ones(len(job.is_mark), dtype=bool)):
        title = "Deposited energy (contours in cyan)"
        if not job.contour.any() or hides(job.contour):
            title = "Deposited energy (path not drawn: it would hide the map; see job.png)"
    if title.endswith("path in cyan)"):
        for mask, style in ((job.is_mark, "-"), (~job.is_mark, "--")):
            pts = job.with_gaps(mask)
            ax.plot(pts[:, 0], pts[:, 1], style, color="cyan", lw=0.6)
    elif title.endswith("contours in cyan)"):
        pts = job.with_gaps(job.contour)
        ax.plot(pts[:, 0], pts[:, 1], "-", color="cyan", lw=0.6)
    fig.colorbar(shown, ax=ax, label="energy density [J/mm²]")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    ax.set_title(title)
    fig.savefig(os.path.join(folder, "energy_map_plot.png"), dpi=120, pil_kwargs=FAST_PNG)
    plt.close(fig)


def plot_speed(folder, trace, job):
    fig, ax = new_figure((9, 4))
    t = trace["t_s"] * 1e3
    ax.plot(t, trace["setpoint_speed_mps"] * 1e3, label="setpoint (Q_filt2)")
    ax.plot(t, trace["actual_speed_mps"] * 1e3, label="actual (after servo)")
    for speed in np.unique(job.speed[job.is_mark]):
        ax.axhline(speed * 1e3, color="grey", ls=":", lw=0.8)
    ax.set_xlabel("time [ms]")
    ax.set_ylabel("spot speed [mm/s]")
    ax.legend(loc="lower right")  # a fixed place: "best" tests every data point against each spot
    ax.grid(alpha=0.3)
    fig.savefig(os.path.join(folder, "speed.png"), dpi=120, pil_kwargs=FAST_PNG)
    plt.close(fig)


def distance_to_path(points, starts, ends, reach=2e-4, max_pieces=300000):
    """Distance from each point to the nearest commanded segment (NaN farther than `reach`).

    The segments are cut into pieces no longer than a cell (2·reach, more on a long path: at most
    about `max_pieces` pieces), binned by their midpoints on a grid of such cells. A piece within
    `reach` of a point has its midpoint within reach + cell/2 of it, so each point is compared
    with the pieces of the cells around its own only: the cost grows with the points and the path
    near them, not with their product.
    """
    out = np.full(len(points), np.inf)
    if len(starts) == 0 or len(points) == 0:
        return np.full(len(points), np.nan)
    d = ends - starts
    length = np.hypot(d[:, 0], d[:, 1])
    size = max(2 * reach, length.sum() / max_pieces)
    near = int(np.ceil((reach + 0.5 * size) / size))  # cells to look at on each side
    pieces = np.maximum(1, np.ceil(length / size)).astype(np.int64)
    owner = np.repeat(np.arange(len(starts)), pieces)
    k = np.arange(len(owner)) - np.repeat(np.cumsum(pieces) - pieces, pieces)
    step = d[owner] / pieces[owner][:, None]
    a = starts[owner] + step * k[:, None]
    finite = np.flatnonzero(np.all(np.isfinite(points), axis=1))
    p_all = points[finite]
    origin = np.minimum(a.min(axis=0), p_all.min(axis=0, initial=np.inf)) - (near + 1) * size
    columns = int(np.ceil((max(a[:, 0].max(), p_all[:, 0].max(initial=-np.inf)) - origin[0]) / size)) + 2 * near + 2
    mc = np.floor((a + 0.5 * step - origin) / size).astype(np.int64)
    cell = mc[:, 1] * columns + mc[:, 0]
    order = np.argsort(cell)
    cell = cell[order]
    pc = np.floor((p_all - origin) / size).astype(np.int64)
    for dy in range(-near, near + 1):
        for dx in range(-near, near + 1):
            want = (pc[:, 1] + dy) * columns + pc[:, 0] + dx
            first = np.searchsorted(cell, want, side="left")
            count = np.searchsorted(cell, want, side="right") - first
            has = np.flatnonzero(count > 0)
            if len(has) == 0:
                continue
            first, count = first[has], count[has]
            group = np.cumsum(count) - count
            piece = order[np.repeat(first, count) + np.arange(count.sum()) - np.repeat(group, count)]
            p = p_all[np.repeat(has, count)]
            pa, pd = a[piece], step[piece]
            t = np.clip(((p - pa) * pd).sum(axis=1) / np.maximum((pd * pd).sum(axis=1), 1e-300), 0.0, 1.0)
            best = np.minimum.reduceat(np.hypot(*(p - pa - t[:, None] * pd).T), group)
            out[finite[has]] = np.minimum(out[finite[has]], best)
    out[~(out <= reach)] = np.nan  # farther: a nearer piece may lie outside the cells looked at
    return out


def plot_contour_error(folder, trace, job):
    starts, ends = job.mark_segments()
    on = np.flatnonzero(trace["power_w"] > 0)
    on = on[::max(1, -(-len(on) // 5000))]  # at most 5000 points: a dot cloud shows no more
    fig, ax = new_figure((9, 4))
    t = trace["t_s"][on] * 1e3
    for name in ("setpoint", "actual"):
        pts = np.column_stack([trace[name + "_x_m"][on], trace[name + "_y_m"][on]])
        err = distance_to_path(pts, starts, ends) * 1e6
        ax.plot(t, err, ".", ms=2, label=name + " (laser on)")
    ax.set_xlabel("time [ms]")
    ax.set_ylabel("distance to the commanded path [µm]")
    ax.legend(loc="upper right")
    ax.grid(alpha=0.3)
    fig.savefig(os.path.join(folder, "contour_error.png"), dpi=120, pil_kwargs=FAST_PNG)
    plt.close(fig)


def worst_corner(path):
    """The corner of metrics.yaml with the highest energy peak (the first of equals), found by a text scan: a whole
    layer lists ~1e5 corners, too many to parse as YAML for one."""
    best, best_peak, block = None, -1.0, None
    with open(path) as f:
        for line in f:
            if line.startswith("  - polyline:"):
                block = [line]
            elif block is not None and line.startswith("    "):
                block.append(line)
                if line.startswith("    energy_peak_jpm2:"):
                    peak = float(line.split(":", 1)[1])
                    if peak > best_peak:
                        best, best_peak = block, peak
            elif block is not None:
                block = None
    return yaml.load("".join(best), Loader=LOADER)[0] if best else None


def plot_corner(folder, trace, job, metrics):
    if not metrics.get("corners"):
        return
    corner = worst_corner(os.path.join(folder, "metrics.yaml"))
    c = np.asarray(corner["point_m"]) * 1e3
    half = max(0.15, 3 * corner["theory"]["max_contour_error_m"] * 1e3)
    fig, ax = new_figure((6, 6), left=0.14, right=0.95, bottom=0.1, top=0.93)
    # The commanded path near the corner only (a whole layer has ~1e6 points).
    near = np.all(np.abs(job.points * 1e3 - c) <= 4 * half, axis=1)
    polyline = np.repeat(np.arange(len(job.is_mark)), np.diff(job.start))
    mask = np.zeros(len(job.is_mark), dtype=bool)
    mask[np.unique(polyline[near])] = True
    pts = job.with_gaps(mask)
    ax.plot(pts[:, 0], pts[:, 1], "k-", lw=1, label="commanded")
    ax.plot(trace["setpoint_x_m"] * 1e3, trace["setpoint_y_m"] * 1e3, label="setpoint (Q_filt2)")
    ax.plot(trace["actual_x_m"] * 1e3, trace["actual_y_m"] * 1e3, label="actual")
    ax.set_xlim(c[0] - half, c[0] + half)
    ax.set_ylim(c[1] - half, c[1] + half)
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    ax.set_title("Highest corner peak, %.3g J/mm²: %.1f° at %.0f mm/s"
                 % (corner["energy_peak_jpm2"] * 1e-6, corner["angle_deg"], corner["programmed_speed_mps"] * 1e3))
    ax.legend(loc="upper left")
    fig.savefig(os.path.join(folder, "corner_zoom.png"), dpi=120, pil_kwargs=FAST_PNG)
    plt.close(fig)


def plot_quality(folder, metrics):
    fig = quality_figure(plt, [(metrics.get("job", "run"), metrics)])
    fig.savefig(os.path.join(folder, "quality.png"), dpi=110, pil_kwargs=FAST_PNG)
    plt.close(fig)


def draw(folder, which, data):
    trace, job, metrics = data
    for name in which:
        if name == "energy":
            plot_energy(folder, job)
        elif name == "quality":
            plot_quality(folder, metrics)
        elif name == "speed":
            plot_speed(folder, trace, job)
        elif name == "contour_error":
            plot_contour_error(folder, trace, job)
        elif name == "corner":
            plot_corner(folder, trace, job, metrics)


DISK_FULL = errno.ENOSPC  # the exit status of a run that found the disk full


def disk_full(error):
    return isinstance(error, OSError) and error.errno in (errno.ENOSPC, errno.EDQUOT)


def fork_draw(folder, which, data):
    """draw() in a forked process (matplotlib is imported already); returns its pid."""
    pid = os.fork()
    if pid == 0:
        code = 1
        try:
            draw(folder, which, data)
            code = 0
        except BaseException as error:
            import traceback
            traceback.print_exc()
            code = DISK_FULL if disk_full(error) else 1
        finally:
            sys.stdout.flush()
            sys.stderr.flush()
            os._exit(code)
    return pid


def plot_folder(folder, plots="all", images_ready=None):
    """Loads the folder's data once, then draws the figures, in forked processes when the machine
    has two cores: the energy map here, the others side by side.

    images_ready: if set, the folder's images (energy_map.*) are not written yet; it returns once
    they are (False: they never will be, no energy plot). The other plots start before it."""
    which = SUMMARY if plots == "summary" else ALL
    data = load(folder)
    if (os.cpu_count() or 1) < 2 or not hasattr(os, "fork"):
        if images_ready is not None and not images_ready():
            which = [n for n in which if n != "energy"]
        draw(folder, which, data)
        return
    # Balanced for the costs on a whole layer: energy ~0.35 s, quality ~0.35 s, contour error
    # ~0.4 s, speed and corner ~0.1 s each (CPU).
    groups = [[n for n in ("quality", "speed", "corner") if n in which], [n for n in ("contour_error",) if n in which]]
    if images_ready is None:
        groups = [[n for n in ("quality", "contour_error") if n in which]]
    own = [n for n in which if not any(n in g for g in groups)]
    pids = [fork_draw(folder, g, data) for g in groups if g]
    statuses = []
    try:
        if images_ready is not None and not images_ready():
            own = [n for n in own if n != "energy"]
        draw(folder, own, data)
    finally:
        statuses = [os.waitpid(pid, 0)[1] for pid in pids]
    if any(os.WIFEXITED(s) and os.WEXITSTATUS(s) == DISK_FULL for s in statuses):
        print("plot_results.py: no space left on device", file=sys.stderr)
        sys.exit(DISK_FULL)
    if any(statuses):
        sys.exit("plot_results.py: a drawing process failed (its message above)")


def warm_up():
    """Loads what the first figure of a process loads (fonts, the Agg canvas, the colour maps), so
    a served run leaves only the drawing."""
    fig, ax = plt.subplots(figsize=(2, 2))
    ax.imshow(np.zeros((4, 4)), cmap="inferno")
    ax.plot([0, 1], [0, 1], ".")
    ax.set_title("µm²")
    fig.colorbar(ax.images[0], ax=ax, label="J/mm²")
    fig.savefig(io.BytesIO(), dpi=20)
    plt.close(fig)


def main(argv):
    plots, serve, folders = "all", False, []
    args = list(argv)
    while args:
        a = args.pop(0)
        if a == "--plots" and args:
            plots = args.pop(0)
        elif a == "--serve":
            serve = True
        else:
            folders.append(a)
    if plots not in ("all", "summary") or len(folders) != (0 if serve else 1):
        sys.exit(__doc__)
    if serve:
        warm_up()
        line = sys.stdin.readline().rstrip("\n")
        if line:  # else: the run ended without results
            plot_folder(line, plots, lambda: sys.stdin.readline().strip() == "images")
        return
    plot_folder(folders[0], plots)

if __name__ == "__main__":
    try:
        main(sys.argv[1:])
    except OSError as error:
        if not disk_full(error):
            raise
        print("plot_results.py: no space left on device: %s" % error, file=sys.stderr)
        sys.exit(DISK_FULL)
