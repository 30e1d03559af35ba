"""Figure of studies/oblique: measured and exact LK reflection amplitudes against the angle.

    /usr/bin/python3 studies/oblique/plot.py OUTDIR

Reads OUTDIR/metrics.json (written by the `oblique` program) and, when present,
OUTDIR/metrics_mpm.json (`oblique --method mpm`), adds the closed-form curves
(docs/physics.md §4.1, a = b = 1) and writes OUTDIR/reflection_vs_angle.png.
"""
import cmath
import json
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def lk(nu, angle, a=1.0, b=1.0):
    """|R_PP|, |R_PS|, |R_SS|, |R_SP| of docs/physics.md §4.1 (same formulas as lk_reflection)."""
    k = math.sqrt((1 - 2 * nu) / (2 * (1 - nu)))
    out = []
    # incident P at `angle`
    th = angle
    ph = math.asin(k * math.sin(th))
    c2p = math.cos(2 * ph)
    D = (c2p + a * math.cos(th)) * (c2p + b * math.cos(ph)) + (k * math.sin(2 * ph) + a * math.sin(ph)) * (
        k * math.sin(2 * th) + b * math.sin(th))
    rpp = ((a * math.cos(th) - c2p) * (c2p + b * math.cos(ph)) + (k * math.sin(2 * ph) + a * math.sin(ph)) * (
        k * math.sin(2 * th) - b * math.sin(th))) / D
    rps = 2 * math.sin(th) * math.cos(th) * (2 * k * c2p - a * b) / D
    # incident SV at `angle`
    ph = angle
    s_th = math.sin(ph) / k
    cos_th = cmath.sqrt(1 - s_th * s_th) if s_th <= 1 else -1j * math.sqrt(s_th * s_th - 1)
    sin2th = 2 * s_th * cos_th
    c2p = math.cos(2 * ph)
    D = (c2p + a * cos_th) * (c2p + b * math.cos(ph)) + (k * math.sin(2 * ph) + a * math.sin(ph)) * (
        k * sin2th + b * s_th)
    rsp = 2 * math.sin(ph) * math.cos(ph) * (2 * k * c2p - a * b) / D
    rss = ((c2p + a * cos_th) * (c2p - b * math.cos(ph)) - (k * sin2th + b * s_th) * (
        k * math.sin(2 * ph) - a * math.sin(ph))) / D
    return abs(rpp), abs(rps), abs(rss), abs(rsp)


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "studies/oblique/out"
    with open(f"{out}/metrics.json") as f:
        m = json.load(f)
    mpm = None
    try:
        with open(f"{out}/metrics_mpm.json") as f:
            mpm = json.load(f)
    except FileNotFoundError:
        pass
    nu = m["nu"]
    ang = np.linspace(0, 80, 161)
    ex = np.array([lk(nu, math.radians(a)) for a in ang])
    fig, axs = plt.subplots(1, 2, figsize=(11, 4.3))
    p = [r for r in m["results"] if r["wave"] == "P"]
    s = [r for r in m["results"] if r["wave"] == "SV"]
    ax = axs[0]
    ax.plot(ang, ex[:, 0], "C0-", label="|R_PP| exact")
    ax.plot(ang, ex[:, 1], "C1-", label="|R_PS| exact")
    ax.plot([r["angle_deg"] for r in p], [r["R_PP"] for r in p], "C0o", label="|R_PP| FEM")
    ax.plot([r["angle_deg"] for r in p], [r["R_PS"] for r in p], "C1s", label="|R_PS| FEM")
    ax.set_title("incident P")
    ax = axs[1]
    ax.plot(ang, ex[:, 2], "C2-", label="|R_SS| exact")
    ax.plot(ang, ex[:, 3], "C3-", label="|R_SP| exact")
    ax.plot([r["angle_deg"] for r in s], [r["R_SS"] for r in s], "C2o", label="|R_SS| FEM")
    trav = [r for r in s if not r["reflected_p_evanescent"]]
    ev = [r for r in s if r["reflected_p_evanescent"]]
    ax.plot([r["angle_deg"] for r in trav], [r["R_SP"] for r in trav], "C3s", label="|R_SP| FEM")
    if ev:
        ax.plot([r["angle_deg"] for r in ev], [r["R_SP"] for r in ev], "C3x",
                label="|R_SP| FEM (evanescent P: not an amplitude)")
    if mpm:
        pm = [r for r in mpm["results"] if r["wave"] == "P"]
        sm = [r for r in mpm["results"] if r["wave"] == "SV" and not r["reflected_p_evanescent"]]
        sm_all = [r for r in mpm["results"] if r["wave"] == "SV"]
        axs[0].plot([r["angle_deg"] for r in pm], [r["R_PP"] for r in pm], "C0^", mfc="none",
                    label="|R_PP| MPM")
        axs[0].plot([r["angle_deg"] for r in pm], [r["R_PS"] for r in pm], "C1v", mfc="none",
                    label="|R_PS| MPM")
        axs[1].plot([r["angle_deg"] for r in sm_all], [r["R_SS"] for r in sm_all], "C2^",
                    mfc="none", label="|R_SS| MPM")
        axs[1].plot([r["angle_deg"] for r in sm], [r["R_SP"] for r in sm], "C3v", mfc="none",
                    label="|R_SP| MPM")
    kappa = math.sqrt((1 - 2 * nu) / (2 * (1 - nu)))
    ax.axvline(math.degrees(math.asin(kappa)), color="0.6", ls=":", lw=1)
    ax.set_title("incident SV (dotted: critical angle)")
    for ax in axs:
        ax.set_xlabel("angle of incidence from the boundary normal (deg)")
        ax.set_ylabel("reflected / incident displacement amplitude")
        ax.set_xlim(0, 80)
        ax.set_ylim(0, 0.8)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle(f"LK dashpots (a = b = 1): FEM far-field (Q1){' and MPM silent layer (1 ppc)' if mpm else ''}, "
                 f"nu = {nu}, Gaussian pulse {m['pulse_fwhm_cells']} cells FWHM; extended-domain differencing",
                 fontsize=10)
    fig.tight_layout()
    fig.savefig(f"{out}/reflection_vs_angle.png", dpi=130)
    print(f"oblique: wrote {out}/reflection_vs_angle.png")


if __name__ == "__main__":
    main()
