"""Figure of studies/oblique: measured and exact LK reflection amplitudes against the angle.

    /usr/bin/python3 studies/oblique/plot.py OUTDIR

Reads OUTDIR/metrics.json (written by the `oblique` program) and, when present,
OUTDIR/metrics_mpm.json (`oblique --method mpm`), adds the closed-form curves
(docs/physics.md §4.1, a = b = 1) and writes OUTDIR/reflection_vs_angle.png.
"""
import cmath
import json
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
import style  # noqa: E402

import matplotlib.pyplot as plt  # noqa: E402

# One colour per reflected wave (style.COLOURS): closed form solid lines, FEM filled markers, MPM
# open markers.
C = {"PP": style.COLOURS[0], "PS": style.COLOURS[1], "SS": style.COLOURS[2], "SP": style.COLOURS[3]}


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
    style.apply()
    ang = np.linspace(0, 80, 161)
    ex = np.array([lk(nu, math.radians(a)) for a in ang])
    fig, axs = plt.subplots(1, 2, figsize=(11, 4.3))
    p = [r for r in m["results"] if r["wave"] == "P"]
    s = [r for r in m["results"] if r["wave"] == "SV"]
    ax = axs[0]
    ax.plot(ang, ex[:, 0], "-", color=C["PP"], label="$|R_{PP}|$ exact")
    ax.plot(ang, ex[:, 1], "--", color=C["PS"], label="$|R_{PS}|$ exact")
    ax.plot([r["angle_deg"] for r in p], [r["R_PP"] for r in p], "o", color=C["PP"], label="$|R_{PP}|$ FEM")
    ax.plot([r["angle_deg"] for r in p], [r["R_PS"] for r in p], "s", color=C["PS"], label="$|R_{PS}|$ FEM")
    ax.set_title("incident P")
    ax = axs[1]
    ax.plot(ang, ex[:, 2], "-", color=C["SS"], label="$|R_{SS}|$ exact")
    ax.plot(ang, ex[:, 3], "--", color=C["SP"], label="$|R_{SP}|$ exact")
    ax.plot([r["angle_deg"] for r in s], [r["R_SS"] for r in s], "o", color=C["SS"], label="$|R_{SS}|$ FEM")
    trav = [r for r in s if not r["reflected_p_evanescent"]]
    ev = [r for r in s if r["reflected_p_evanescent"]]
    ax.plot([r["angle_deg"] for r in trav], [r["R_SP"] for r in trav], "s", color=C["SP"],
            label="$|R_{SP}|$ FEM")
    if ev:
        ax.plot([r["angle_deg"] for r in ev], [r["R_SP"] for r in ev], "x", color=C["SP"],
                label="$|R_{SP}|$ FEM (evanescent P: not an amplitude)")
    if mpm:
        pm = [r for r in mpm["results"] if r["wave"] == "P"]
        sm = [r for r in mpm["results"] if r["wave"] == "SV" and not r["reflected_p_evanescent"]]
        sm_all = [r for r in mpm["results"] if r["wave"] == "SV"]
        axs[0].plot([r["angle_deg"] for r in pm], [r["R_PP"] for r in pm], "^", color=C["PP"],
                    mfc="none", label="$|R_{PP}|$ MPM")
        axs[0].plot([r["angle_deg"] for r in pm], [r["R_PS"] for r in pm], "v", color=C["PS"],
                    mfc="none", label="$|R_{PS}|$ MPM")
        axs[1].plot([r["angle_deg"] for r in sm_all], [r["R_SS"] for r in sm_all], "^",
                    color=C["SS"], mfc="none", label="$|R_{SS}|$ MPM")
        axs[1].plot([r["angle_deg"] for r in sm], [r["R_SP"] for r in sm], "v", color=C["SP"],
                    mfc="none", label="$|R_{SP}|$ MPM")
    kappa = math.sqrt((1 - 2 * nu) / (2 * (1 - nu)))
    ax.axvline(math.degrees(math.asin(kappa)), color="0.6", ls=":", lw=1)
    ax.set_title("incident SV (dotted: critical angle)")
    for ax in axs:
        ax.set_xlabel("angle of incidence from the boundary normal (°)")
        ax.set_ylabel("reflected / incident displacement amplitude")
        ax.set_xlim(0, 80)
        ax.set_ylim(0, 0.8)
    fig.suptitle(f"LK dashpots (a = b = 1): FEM far-field (Q1){' and MPM silent layer (1 ppc)' if mpm else ''}, "
                 f"ν = {nu}, Gaussian pulse {m['pulse_fwhm_cells']} cells FWHM\nmeasured by extended-domain differencing")
    fig.tight_layout()
    for ax in axs:  # under each panel, where it covers no curve (the tight bounding box takes it in)
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=2)
    fig.savefig(f"{out}/reflection_vs_angle.png")
    print(f"oblique: wrote {out}/reflection_vs_angle.png")


if __name__ == "__main__":
    main()
