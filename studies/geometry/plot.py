"""Figures and metrics.json of the geometry study (called by studies/geometry/run).

  inclined_reflection.png  |R_PP| and |R_PS| of the 30-degree silent edge against the pulse width,
                           with the closed form (docs/physics.md §4.1) and the free-edge check
  ring_history.png         radial stress at P (30 mm from the centre of the ring) for the free,
                           silent and extended outer circle
  ring_energy.png          energy left in the ring / absorbed by the silent ring over time
  ring_circle.png          sigma_rr around the circle r = 30 mm (probe C along a gmsh curve):
                           relative L2 vs extended by angle, and the direct wave's peak by angle
  metrics.json             every number of the README
"""
import argparse
import csv
import json
import math
import os

import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
import style  # noqa: E402
from history import compare, read_history as columns  # noqa: E402

import matplotlib.pyplot as plt  # noqa: E402

BLUE, RED, GREEN = style.COLOURS[0], style.COLOURS[1], style.COLOURS[2]


def read_csv(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return rows


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--bin", required=True)
    args = ap.parse_args()
    out = args.out
    metrics = {}
    style.apply()

    # ---- inclined edge ----
    rows = read_csv(os.path.join(out, "inclined_widths.csv"))
    opt = lambda name: read_csv(os.path.join(out, name)) if os.path.exists(os.path.join(out, name)) else []  # noqa: E731
    depths, variants = opt("inclined_depths.csv"), opt("inclined_variants.csv")
    f = lambda r, k: float(r[k])  # noqa: E731
    disp = lambda rs: [r for r in rs if r["measure"] == "displacement"]  # noqa: E731
    free = [r for r in disp(rows) if f(r, "a") == 0]
    normal = [r for r in disp(rows) if f(r, "theta_deg") == 0]
    silent30 = lambda rs: sorted([r for r in rs if f(r, "a") == 1 and f(r, "theta_deg") == 30],  # noqa: E731
                                 key=lambda r: (f(r, "fwhm_cells"), f(r, "depth0_cells")))
    silent = silent30(disp(rows))
    silent_v = silent30([r for r in rows if r["measure"] == "velocity"])
    row = lambda r: {"fwhm_cells": f(r, "fwhm_cells"), "receivers_cells": [f(r, "depth0_cells"), f(r, "depth1_cells")],  # noqa: E731
                     "rpp": f(r, "rpp"), "rps": f(r, "rps"),
                     "rpp_rel_error": f(r, "rpp") / f(r, "rpp_exact") - 1 if f(r, "rpp_exact") > 0 else None,
                     "rps_rel_error": f(r, "rps") / f(r, "rps_exact") - 1 if f(r, "rps_exact") > 0 else None,
                     "particles": int(f(r, "particles_a")) + int(f(r, "particles_b")),
                     "wall_seconds": f(r, "wall_seconds")}
    inc = {"method": "extended-domain differencing, div/curl of the particle-displacement difference on "
                     "the particle lattice (R are displacement-amplitude ratios, docs/physics.md §4.1), "
                     "receivers 8-12 cells inside the edge unless stated, 4 ppc, aluminium (nu = 0.33), "
                     "sin^2 pulse",
           "closed_form_30deg": {"rpp": f(silent[0], "rpp_exact"), "rps": f(silent[0], "rps_exact")},
           "free_edge_30deg": [dict(row(r), rpp_exact=f(r, "rpp_exact"), rps_exact=f(r, "rps_exact")) for r in free],
           "silent_edge_0deg": [row(r) for r in normal],
           "silent_edge_30deg": [row(r) for r in silent],
           "silent_edge_30deg_velocity_measure": [row(r) for r in silent_v],
           "silent_edge_30deg_receiver_depth": [row(r) for r in silent30(depths)],
           "silent_edge_30deg_variants": [dict(row(r), form=r["form"], anchor=r["anchor"]) for r in variants
                                          if f(r, "a") == 1],
           "edge_30deg_other_lk_coefficients": [dict(row(r), a=f(r, "a"), b=f(r, "b"), rpp_exact=f(r, "rpp_exact"),
                                                     rps_exact=f(r, "rps_exact")) for r in variants if f(r, "a") != 1]}
    metrics["inclined_30deg"] = inc

    fig, axs = plt.subplots(1, 2, figsize=(10.5, 4.4))
    ax = axs[0]
    w = [f(r, "fwhm_cells") for r in silent]
    ax.loglog(w, [f(r, "rpp") for r in silent], "o-", color=BLUE, label=r"$|R_{PP}|$ (div u)")
    ax.loglog(w, [f(r, "rps") for r in silent], "s-", color=RED, label=r"$|R_{PS}|$ (curl u)")
    wv = [f(r, "fwhm_cells") for r in silent_v]
    ax.loglog(wv, [f(r, "rpp") for r in silent_v], "o--", color=BLUE, alpha=0.5, mfc="none",
              label=r"$|R_{PP}|$ on velocities")
    ax.loglog(wv, [f(r, "rps") for r in silent_v], "s--", color=RED, alpha=0.5, mfc="none",
              label=r"$|R_{PS}|$ on velocities")
    ax.axhline(f(silent[0], "rpp_exact"), color=BLUE, ls=":", label=r"$|R_{PP}|$ closed form")
    ax.axhline(f(silent[0], "rps_exact"), color=RED, ls=":", label=r"$|R_{PS}|$ closed form")
    for r in [r for r in variants if f(r, "a") == 1]:
        ax.plot([f(r, "fwhm_cells")], [f(r, "rpp")], "x", color=BLUE, ms=8)
        ax.plot([f(r, "fwhm_cells")], [f(r, "rps")], "+", color=RED, ms=9)
    ax.set_xlabel("pulse width (FWHM, cells)")
    ax.set_ylabel("reflected amplitude / incident")
    ax.set_title("Silent edge at 30° (aluminium, 4 ppc), receivers 8-12 cells deep\n"
                 "x, +: anchor at the particle (nodal and paper forms)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    ax = axs[1]
    dr = silent30(depths)
    if dr:
        dm = [0.5 * (f(r, "depth0_cells") + f(r, "depth1_cells")) for r in dr]
        ax.plot(dm, [f(r, "rpp") for r in dr], "o-", color=BLUE, label=r"$|R_{PP}|$")
        ax.plot(dm, [f(r, "rps") for r in dr], "s-", color=RED, label=r"$|R_{PS}|$")
        ax.axhline(f(dr[0], "rpp_exact"), color=BLUE, ls=":")
        ax.axhline(f(dr[0], "rps_exact"), color=RED, ls=":")
        ax.set_ylim(0, None)
        ax.set_xlabel("receiver depth below the edge (cells, band centre)")
        ax.set_ylabel("reflected amplitude / incident")
        ax.set_title("FWHM 16 cells: the excess is a near field of the edge\n"
                     "dotted: closed form")
        ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(out, "inclined_reflection.png"))
    plt.close(fig)

    # ---- ring ----
    ring = {}
    hist = {k: os.path.join(out, f"ring_{k}", "history.csv") for k in ("free", "silent", "extended")}
    t_end = 3e-5
    for k in ("free", "silent", "extended"):
        s = json.load(open(os.path.join(out, f"ring_{k}", "summary.json")))
        e = s["energy"]
        ring[k] = {"external_work_J": e["external_work"], "kinetic_J": e["kinetic"], "elastic_J": e["elastic"],
                   "absorbed_J": e["absorbed"],
                   "left_in_body_fraction": (e["kinetic"] + e["elastic"]) / e["external_work"],
                   "absorbed_fraction": e["absorbed"] / e["external_work"],
                   "energy_imbalance_fraction": e["imbalance"] / e["external_work"],
                   "particles": s["particles"], "wall_seconds": s["wall_seconds"]}
    for k in ("free", "silent"):
        ring[k]["P_srr_L2_vs_extended"] = compare(args.bin, hist[k], hist["extended"], "P.sxx", 0, t_end)
        ring[k]["Q_syy_L2_vs_extended"] = compare(args.bin, hist[k], hist["extended"], "Q.syy", 0, t_end)
    metrics["ring"] = ring

    # sigma_rr around the circle r = 30 mm: probe C along the gmsh curve "probe_circle" (24 points
    # every 15 degrees, counter-clockwise from +x; positions from probes.csv).
    circle = None
    if os.path.exists(os.path.join(out, "ring_silent", "probes.csv")):
        pts = [r for r in read_csv(os.path.join(out, "ring_silent", "probes.csv")) if r["along"] == "C"]

        def srr(c, r):
            th = math.atan2(float(r["y"]), float(r["x"]))
            cs, sn = math.cos(th), math.sin(th)
            n = r["name"]
            return [a * cs * cs + b * sn * sn + 2 * d * sn * cs
                    for a, b, d in zip(c[n + ".sxx"], c[n + ".syy"], c[n + ".sxy"])]

        cols = {k: columns(hist[k]) for k in ("free", "silent", "extended")}
        angles = [math.degrees(math.atan2(float(r["y"]), float(r["x"]))) % 360 for r in pts]
        circle = {"angles_deg": angles}
        ext = [srr(cols["extended"], r) for r in pts]
        for k in ("free", "silent"):
            assert cols[k]["time"] == cols["extended"]["time"]
            l2 = []
            for r, e in zip(pts, ext):
                v = srr(cols[k], r)
                l2.append(math.sqrt(sum((a - b) ** 2 for a, b in zip(v, e)) / sum(b * b for b in e)))
            circle[k] = {"srr_L2_vs_extended": l2, "min": min(l2), "max": max(l2),
                         "mean": sum(l2) / len(l2)}
        peaks = [max(-v for v in e) for e in ext]  # the direct wave is compressive
        circle["extended_peak_compression_MPa"] = [p / 1e6 for p in peaks]
        circle["extended_peak_spread"] = (max(peaks) - min(peaks)) / (sum(peaks) / len(peaks))
        metrics["ring"]["circle_r30mm"] = circle

    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    # (colour, dashes, label); the extended ring is the reference, a wide light-grey band under
    # the others (as in the pulse study's Figs. 5-7).
    look = {"free": (RED, "--", "free outer circle"), "silent": (BLUE, "-", "silent outer circle"),
            "extended": ("0.72", "-", "extended ring (R = 150 mm, reference)")}
    for k in ("extended", "free", "silent"):
        c = columns(hist[k])
        ax.plot([t * 1e6 for t in c["time"]], [v / 1e6 for v in c["P.sxx"]], color=look[k][0], ls=look[k][1],
                label=look[k][2], **(dict(lw=3.6, zorder=1) if k == "extended" else {}))
    ax.set_xlabel("time (µs)")
    ax.set_ylabel(r"$\sigma_{rr}$ at P (MPa)")
    ax.set_title("Ring a = 10 mm, R = 50 mm, 100 MPa pressure pulse in the hole")
    fig.tight_layout()
    # The legend outside on the right, added after the layout: it covers no curve.
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0)
    fig.savefig(os.path.join(out, "ring_history.png"))
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    for k in ("free", "silent"):
        c = columns(hist[k])
        t = [x * 1e6 for x in c["time"]]
        W = ring[k]["external_work_J"]
        left = [(a + b) / W for a, b in zip(c["energy.kinetic"], c["energy.elastic"])]
        ax.plot(t, left, color=look[k][0], ls=look[k][1], label=f"{k}: energy in the ring")
        if k == "silent":
            ax.plot(t, [a / W for a in c["energy.absorbed"]], color=GREEN, ls="-.",
                    label="silent: absorbed")
    ax.set_xlabel("time (µs)")
    ax.set_ylabel("fraction of the work of the pressure")
    ax.set_title("Ring: energy left in the ring, and absorbed by the silent circle")
    fig.tight_layout()
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0)
    fig.savefig(os.path.join(out, "ring_energy.png"))
    plt.close(fig)

    if circle:
        fig, axes = plt.subplots(1, 2, figsize=(11, 4))
        for k in ("free", "silent"):
            axes[0].plot(circle["angles_deg"], circle[k]["srr_L2_vs_extended"], "o" + look[k][1],
                         color=look[k][0], ms=4, label=look[k][2])
        axes[0].set_yscale("log")
        axes[0].set_xlabel("angle on the circle r = 30 mm (degrees from +x)")
        axes[0].set_ylabel(r"relative L2 of $\sigma_{rr}$ vs extended, 0-30 µs")
        axes[0].set_xticks(range(0, 361, 45))
        axes[0].grid(True, alpha=0.3, which="both")
        axes[0].legend()
        axes[1].plot(circle["angles_deg"], circle["extended_peak_compression_MPa"], "ko-", ms=4)
        axes[1].set_xlabel("angle on the circle r = 30 mm (degrees from +x)")
        axes[1].set_ylabel(r"peak compression $-\sigma_{rr}$ of the direct wave (MPa)")
        axes[1].set_xticks(range(0, 361, 45))
        axes[0].set_title("silent and free circle against the extended ring")
        axes[1].set_title("the direct wave in the extended ring")
        fig.suptitle("Ring: 24 points of a probe along the gmsh curve \"probe_circle\" (r = 30 mm)")
        fig.tight_layout()
        fig.savefig(os.path.join(out, "ring_circle.png"))
        plt.close(fig)

    with open(os.path.join(out, "metrics.json"), "w") as fo:
        json.dump(metrics, fo, indent=2)
    print(json.dumps(metrics, indent=2))


if __name__ == "__main__":
    main()
