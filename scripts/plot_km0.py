#!/usr/bin/env python3
"""Plots of a KM0 report folder (THESIS 2.4, Fig. 2.57-2.60).

usage: plot_km0.py KM0_DIR

Reads km0_signal.csv, km0_steps.csv, km0_ramps.csv and km0_report.yaml written by km0Report()
(scanhead_galvo km0) and writes next to them:
  km0_signal.png           the whole excitation: setpoint and response angle, speed, current
  km0_ramps.png            ramp section: position/setpoint, following error, current
  km0_steps.png            zoom on every step: normalised response, +-5 % band, start delay, settling
  km0_friction.png         friction torque Kc*i vs steady speed, model line B*w + Tp + Tc*sgn(w)
  km0_following_error.png  following error at the ramp ends vs speed (THESIS Fig. 2.60b)
"""
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import yaml  # noqa: E402

DEG = 180.0 / np.pi


def read_csv(path):
    with open(path) as f:
        header = f.readline().strip().split(",")
    rows = []
    with open(path) as f:
        f.readline()
        for line in f:
            rows.append(line.strip().split(","))
    cols = {}
    for i, name in enumerate(header):
        vals = [r[i] for r in rows]
        try:
            cols[name] = np.array([float(v) for v in vals])
        except ValueError:
            cols[name] = np.array(vals)
    return cols


def main(folder):
    sig = np.loadtxt(os.path.join(folder, "km0_signal.csv"), delimiter=",", skiprows=1)
    t, target, sp, sp_v, _, pos, vel, cur, fe, phase = sig.T
    steps = read_csv(os.path.join(folder, "km0_steps.csv"))
    ramps = read_csv(os.path.join(folder, "km0_ramps.csv"))
    with open(os.path.join(folder, "km0_report.yaml")) as f:
        report = yaml.safe_load(f)
    axis = report.get("axis", "?")
    kc = float(report["torque_constant_nm_per_a"])
    fr = {k: float(v) for k, v in report["axis_friction"].items()}
    ts = t[1] - t[0]

    # Whole signal (THESIS Fig. 2.57).
    fig, ax = plt.subplots(3, 1, figsize=(11, 8), sharex=True)
    ax[0].plot(t, sp * DEG, label="setpoint")
    ax[0].plot(t, pos * DEG, "--", label="response")
    ax[0].set_ylabel("angle [deg]")
    ax[0].legend(loc="upper right")
    ax[1].plot(t, sp_v, label="setpoint")
    ax[1].plot(t, np.gradient(pos, ts), "--", label="response (dθ/dt)")
    ax[1].set_ylabel("speed [rad/s]")
    ax[1].legend(loc="upper right")
    ax[2].plot(t, cur)
    ax[2].set_ylabel("current [A]")
    ax[2].set_xlabel("t [s]")
    fig.suptitle(f"KM0 excitation and response, axis {axis}: small steps, large steps, ramps")
    fig.tight_layout()
    fig.savefig(os.path.join(folder, "km0_signal.png"), dpi=110)
    plt.close(fig)

    # Ramp section: position/setpoint, following error, current.
    if len(ramps.get("t_s", [])) > 0:
        t0 = ramps["t_s"].min() - 2e-3
        sel = t >= t0
        fig, ax = plt.subplots(3, 1, figsize=(11, 8), sharex=True)
        ax[0].plot(t[sel], sp[sel] * DEG, label="setpoint")
        ax[0].plot(t[sel], pos[sel] * DEG, "--", label="response")
        ax[0].set_ylabel("angle [deg]")
        ax[0].legend(loc="upper right")
        ax[1].plot(t[sel], fe[sel] * DEG)
        ends = ramps["t_s"] + ramps["ramp_end_time_s"]
        ax[1].plot(ends, np.sign(ramps["command_speed_radps"]) * ramps["following_error_rad"] * DEG, "ro",
                   ms=4, label="ramp end")
        ax[1].set_ylabel("following error [deg]")
        ax[1].legend(loc="upper right")
        ax[2].plot(t[sel], cur[sel])
        ax[2].plot(ends, ramps["steady_current_a"], "ro", ms=4, label="steady current")
        ax[2].set_ylabel("current [A]")
        ax[2].set_xlabel("t [s]")
        ax[2].legend(loc="upper right")
        fig.suptitle(f"KM0 ramps, axis {axis}")
        fig.tight_layout()
        fig.savefig(os.path.join(folder, "km0_ramps.png"), dpi=110)
        plt.close(fig)

    # Step zooms (THESIS Fig. 2.58).
    n = len(steps.get("t_s", []))
    if n > 0:
        cols = 4
        rows = int(np.ceil(n / cols))
        fig, axs = plt.subplots(rows, cols, figsize=(3.2 * cols, 2.5 * rows), squeeze=False)
        for i in range(n):
            a = axs[i // cols][i % cols]
            tb = steps["t_s"][i]
            settle = steps["settling_time_s"][i]
            span = max(1.5e-3, 1.3 * settle if np.isfinite(settle) else 3e-3)
            sel = (t >= tb - 1e-4) & (t <= tb + span)
            x0 = pos[int(round(tb / ts))]
            amp = steps["steady_rad"][i] - x0
            a.plot((t[sel] - tb) * 1e3, (sp[sel] - x0) / amp, label="setpoint")
            a.plot((t[sel] - tb) * 1e3, (pos[sel] - x0) / amp, label="response")
            a.axhspan(0.95, 1.05, color="g", alpha=0.15)
            if np.isfinite(settle):
                a.axvline(settle * 1e3, color="g", lw=0.8)
            d = steps["start_delay_s"][i]
            if np.isfinite(d):
                a.axvline(d * 1e3, color="r", lw=0.8)
            a.set_title(f"{steps['kind'][i]} {(steps['to_rad'][i] - steps['from_rad'][i]) * DEG:+.3g}°\n"
                        f"OS {steps['overshoot_pct'][i]:.2f}%  ts {settle * 1e3:.3f} ms  "
                        f"[{steps['verdict'][i]}]", fontsize=8)
            a.tick_params(labelsize=7)
            a.set_xlabel("t − command [ms]", fontsize=7)
        for j in range(n, rows * cols):
            axs[j // cols][j % cols].axis("off")
        fig.suptitle(f"KM0 steps, axis {axis} (normalised; green: ±5 % band and settling, red: start delay)")
        fig.tight_layout()
        fig.savefig(os.path.join(folder, "km0_steps.png"), dpi=100)
        plt.close(fig)

    # Friction torque vs speed with the model line (THESIS Fig. 2.60a).
    if len(ramps.get("t_s", [])) > 0:
        w = ramps["steady_speed_radps"]
        tq = ramps["friction_torque_nm"]
        wl = np.linspace(min(w.min(), 0.0), max(w.max(), 0.0), 400)
        model = fr["viscous_nms"] * wl + fr["offset_torque_nm"] + fr["coulomb_torque_nm"] * np.sign(wl)
        fig, ax = plt.subplots(figsize=(7, 4.5))
        ax.plot(wl, model * 1e3, "k-", lw=1, label="model B·ω + Tp + Tc·sgn(ω)")
        fit = report.get("friction_fit", {})
        if fit.get("valid"):
            mf = (float(fit["viscous_nms"]) * wl + float(fit["offset_torque_nm"])
                  + float(fit["coulomb_torque_nm"]) * np.sign(wl))
            ax.plot(wl, mf * 1e3, "b:", lw=1, label="least-squares fit of the ramps")
        ax.plot(w, tq * 1e3, "ro", ms=5, label=f"Kc·i at steady speed (Kc = {kc:g} N·m/A)")
        ax.set_xlabel("steady speed ω [rad/s]")
        ax.set_ylabel("friction torque [mN·m]")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        ax.set_title(f"KM0 friction torque, axis {axis}")
        fig.tight_layout()
        fig.savefig(os.path.join(folder, "km0_friction.png"), dpi=110)
        plt.close(fig)

        # Following error vs speed (THESIS Fig. 2.60b).
        mm = float(report.get("metric", {}).get("plane_mm_per_deg", 0) or 0)
        fig, ax = plt.subplots(figsize=(7, 4.5))
        ax.plot(np.abs(ramps["command_speed_radps"]), ramps["following_error_rad"] * DEG, "o")
        ax.set_xlabel("ramp speed |v| [rad/s]")
        ax.set_ylabel("following error at ramp end [deg]")
        ax.grid(alpha=0.3)
        if mm > 0:
            sec = ax.secondary_yaxis("right", functions=(lambda d: d * mm, lambda m: m / mm))
            sec.set_ylabel("[mm at the plane]")
        ax.set_title(f"KM0 following error vs speed, axis {axis}")
        fig.tight_layout()
        fig.savefig(os.path.join(folder, "km0_following_error.png"), dpi=110)
        plt.close(fig)


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
