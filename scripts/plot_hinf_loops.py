#!/usr/bin/env python3
"""The H-infinity loop of one axis in the style of the THESIS's Fig. 3.5.

Usage: plot_hinf_loops.py DIR   (reads DIR/hinf_bode.csv written by `scanhead_galvo loops
--position-controller hinf --out DIR`; writes DIR/hinf_loops.png). Six panels: the four shaped
transfers S, KS, SG, T of the H-infinity loop with their templates gamma/|W| (dashed), the
controller before and after the reduction (order 9 -> integrator + 7), and the open loops of the
H-infinity and conventional (PD + speed PI) structures. Frequency in Hz up to 0.9 of the
controller's Nyquist frequency; magnitudes below -150 dB are cut off.
"""
import os
import sys

import numpy as np
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    out = sys.argv[1]
    d = np.genfromtxt(os.path.join(out, "hinf_bode.csv"), delimiter=",", names=True)
    f = d["frequency_hz"]
    fig, axes = plt.subplots(2, 3, figsize=(15, 8.5))
    panels = [
        ("s_hinf_db", "s_template_db", "s_pd_db", "(a) S = 1/(1+KG)", "dB"),
        ("ks_hinf_db", "ks_template_db", None, "(b) KS: command per reference", "dB A/deg"),
        ("sg_hinf_db", "sg_template_db", None, "(c) SG: error per input disturbance", "dB deg/A"),
        ("t_hinf_db", "t_template_db", "t_pd_db", "(d) T = KG/(1+KG)", "dB"),
    ]
    for ax, (key, tmpl, pd, title, unit) in zip(axes.flat, panels):
        ax.semilogx(f, d[key], color="tab:red", lw=1.4, label="H-infinity")
        ax.semilogx(f, d[tmpl], "--", color="k", lw=1.0, label="template gamma/|W|")
        if pd is not None:
            ax.semilogx(f, d[pd], color="tab:blue", lw=1.0, alpha=0.8, label="conventional (PD + speed PI)")
        ax.set_title(title)
        ax.set_ylabel("magnitude [%s]" % unit)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(loc="best", fontsize=8)
    ax = axes.flat[4]
    ax.semilogx(f, d["k_full_db"], color="0.4", lw=2.2, label="central controller (order 9)")
    ax.semilogx(f, d["k_reduced_db"], color="tab:red", lw=1.0, label="implemented (integrator + 7)")
    ax.set_title("(e) H-infinity controller K, gain")
    ax.set_ylabel("magnitude [dB A/deg]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    ax = axes.flat[5]
    ax.semilogx(f, d["l_hinf_db"], color="tab:red", lw=1.4, label="H-infinity: KG")
    ax.semilogx(f, d["l_pd_db"], color="tab:blue", lw=1.0, label="conventional: L_theta")
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_title("(f) open loops, gain")
    ax.set_ylabel("magnitude [dB]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    for ax in axes.flat:
        low, high = ax.get_ylim()
        ax.set_ylim(max(low, -150.0), high)
    for ax in axes[1]:
        ax.set_xlabel("frequency [Hz]")
    fig.suptitle("H-infinity position loop (THESIS Fig. 3.5 style); templates at the synthesis gamma")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "hinf_loops.png"), dpi=110)


if __name__ == "__main__":
    main()
