#!/usr/bin/env python3
"""Bode plots of the galvo identification: measured (H1), fitted forms and true plant.

Usage: plot_bode.py DIR   (reads DIR/bode.csv written by identificationReport; writes
DIR/bode_theta_current.png and DIR/bode_current_voltage.png). Magnitude in dB, phase in degrees
(unwrapped), frequency log scale; the coherence of the measurement is drawn under the phase.
"""
import os
import sys

import numpy as np
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def load(path):
    data = np.genfromtxt(path, delimiter=",", names=True)
    return {name: data[name] for name in data.dtype.names}


def unwrap_deg(phase_deg):
    return np.degrees(np.unwrap(np.radians(phase_deg)))


def plot(d, prefix, title, unit, out):
    f = d["frequency_hz"]
    fig, (ax_mag, ax_ph, ax_coh) = plt.subplots(3, 1, sharex=True, figsize=(8, 8.5),
                                                gridspec_kw={"height_ratios": [3, 3, 1]})
    ax_mag.semilogx(f, d[prefix + "_meas_db"], ".", ms=2, color="0.55", label="measured (H1, Welch)")
    ax_mag.semilogx(f, d[prefix + "_true_db"], "--", color="tab:blue", lw=1.2, label="true plant")
    ax_mag.semilogx(f, d[prefix + "_fit_db"], "-", color="tab:red", lw=1.0, label="fitted form")
    ax_mag.set_ylabel("magnitude [dB %s]" % unit)
    ax_mag.set_title(title)
    ax_mag.grid(True, which="both", alpha=0.3)
    ax_mag.legend(loc="best", fontsize=8)
    ax_ph.semilogx(f, unwrap_deg(d[prefix + "_meas_deg"]), ".", ms=2, color="0.55")
    ax_ph.semilogx(f, unwrap_deg(d[prefix + "_true_deg"]), "--", color="tab:blue", lw=1.2)
    ax_ph.semilogx(f, unwrap_deg(d[prefix + "_fit_deg"]), "-", color="tab:red", lw=1.0)
    ax_ph.set_ylabel("phase [deg]")
    ax_ph.grid(True, which="both", alpha=0.3)
    ax_coh.semilogx(f, d[prefix + "_coherence"], "-", color="tab:green", lw=0.8)
    ax_coh.set_ylim(0, 1.05)
    ax_coh.set_ylabel("coherence")
    ax_coh.set_xlabel("frequency [Hz]")
    ax_coh.grid(True, which="both", alpha=0.3)
    if prefix == "current":
        ax_ph.text(0.01, 0.03, "measured i/U includes the driver's zero-order hold (half-sample delay);\n"
                   "the fit is made on the exact ZOH equivalent of the form, drawn here continuous",
                   transform=ax_ph.transAxes, fontsize=7, color="0.3")
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: plot_bode.py DIR")
    folder = sys.argv[1]
    d = load(os.path.join(folder, "bode.csv"))
    plot(d, "theta", "theta / i", "rad/A", os.path.join(folder, "bode_theta_current.png"))
    plot(d, "current", "i / U", "A/V", os.path.join(folder, "bode_current_voltage.png"))


if __name__ == "__main__":
    main()
