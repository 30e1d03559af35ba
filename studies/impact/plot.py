"""Figures 8-10 and metrics.json of the oblique impact study (called by studies/impact/run).

Reads the case files (materials, probes), the body extents from OUTDIR/<bc>/summary.json
("bodies": the gmsh surfaces of meshes/impact*.geo as built), OUTDIR/<bc>/history.csv and
OUTDIR/multi_<bc>/history.csv for bc in free, silent, extended. The comparison window of each
probe is computed from the geometry and the steel's P-wave speed: it ends when the first wave
reflected at the extended plate's far end can reach the probe (image-point distance from the
contact face), less 10 cells of travel (the discrete front runs ahead of x/c). The relative L2
differences use `silentmpm compare`, the same implementation as the tests.
"""
import argparse
import json
import math
import os

import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
import style  # noqa: E402
from history import compare, read_history as read  # noqa: E402

import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.colors import to_rgba  # noqa: E402
from matplotlib.patches import Rectangle  # noqa: E402

BCS = ("free", "silent", "extended")
# (look, label): the extended run is the reference, a wide light-grey band under the others (as in
# the pulse study's Figs. 5-7); the truncated plates in colours of style.COLOURS.
STYLE = {"free": (dict(color=style.COLOURS[1], ls="--"), "free boundary"),
         "silent": (dict(color=style.COLOURS[0], ls="-"), "silent boundary"),
         "extended": (dict(color="0.72", ls="-", lw=3.6, zorder=1), "extended region (reference)")}
LABEL = {"free": "free boundary", "silent": "silent boundary", "extended": "extended region"}
MARGIN_CELLS = 10


def p_wave_speed(m):
    e, nu, rho = m["young"], m["poisson"], m["density"]
    lam = e * nu / ((1 + nu) * (1 - 2 * nu))
    mu = e / (2 * (1 + nu))
    return math.sqrt((lam + 2 * mu) / rho)


def body(case, name):
    return next(b for b in case["bodies"] if b["name"] == name)


def window(case_ext, probe, h):
    """End of the reflection-free window of the extended run at `probe`."""
    fl = body(case_ext, "flyer")["box"]
    tg = body(case_ext, "target")["box"]
    c = p_wave_speed(case_ext["materials"][body(case_ext, "target")["material"]])
    x, y = probe
    xi = 2 * tg[2] - x  # image of the probe across the far end
    # nearest point of the contact face x = tg[0], y in [fl[1], fl[3]]
    yc = min(max(y, fl[1]), fl[3])
    d = math.hypot(xi - tg[0], y - yc)
    return d / c, (d - MARGIN_CELLS * h) / c, c, d


def first_reflection_window(case_trunc, probe, h):
    """End of the window holding the direct wave and the first reflection from the truncated
    plate's right side at `probe`: that reflection's arrival (image point across the right side)
    plus the contact duration 2 d_flyer / c_d,flyer, plus 10 cells of travel."""
    fl = body(case_trunc, "flyer")
    tg = body(case_trunc, "target")["box"]
    c = p_wave_speed(case_trunc["materials"][body(case_trunc, "target")["material"]])
    c1 = p_wave_speed(case_trunc["materials"][fl["material"]])
    x, y = probe
    yc = min(max(y, fl["box"][1]), fl["box"][3])
    d = math.hypot(2 * tg[2] - x - tg[0], y - yc)
    tc = 2 * (fl["box"][2] - fl["box"][0]) / c1
    return d / c + tc + MARGIN_CELLS * h / c, d / c, tc


def figure8(cases, probes, path):
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.6), gridspec_kw={"width_ratios": [1.3, 1.3, 2.6]})
    for ax, bc, tag in zip(axes, BCS, "abc"):
        case = cases[bc]
        fl = body(case, "flyer")["box"]
        tg = body(case, "target")["box"]
        ax.add_patch(Rectangle((fl[0], fl[1]), fl[2] - fl[0], fl[3] - fl[1], fc=to_rgba(style.COLOURS[5], 0.35),
                               ec="k", label="aluminium"))
        ax.add_patch(Rectangle((tg[0], tg[1]), tg[2] - tg[0], tg[3] - tg[1], fc="#dddddd", ec="k",
                               label="steel"))
        ax.annotate("", xy=(fl[2] - 0.002, 0.5 * (fl[1] + fl[3])),
                    xytext=(fl[0] - 0.018, 0.5 * (fl[1] + fl[3])),
                    arrowprops=dict(arrowstyle="->", lw=1.5))
        ax.text(fl[0] - 0.018, 0.5 * (fl[1] + fl[3]) + 0.004, "10 m/s", fontsize=8)
        if bc == "extended":
            xt = body(cases["silent"], "target")["box"][2]
            ax.plot([xt, xt], [tg[1], tg[3]], color="gray", ls="--", lw=1)
            ax.text(xt + 0.002, tg[1] + 0.004, "x of the truncated\nright side", fontsize=7,
                    color="gray")
        if bc == "silent":
            ax.plot([tg[2], tg[2]], [tg[1], tg[3]], color=style.COLOURS[0], lw=4, label="silent layer")
        for name, (x, y) in probes.items():
            ax.plot(x, y, "ko", ms=4)
            ax.text(x + 0.002, y + 0.002, name, fontsize=10)
        ax.set_xlim(-0.045, tg[2] + 0.01)
        ax.set_ylim(-0.01, 0.11)
        ax.set_aspect("equal")
        ax.grid(False)
        ax.set_title(f"({tag}) {LABEL[bc]}")
        ax.set_xlabel("x (m)")
        if tag == "a":
            ax.set_ylabel("y (m)")
            ax.legend(fontsize=7, loc="lower left")
        ax.text(fl[0], fl[3] + 0.003, f"{fl[2]-fl[0]:.2f} × {fl[3]-fl[1]:.2f}", fontsize=7)
        ax.text(tg[0] + 0.003, tg[3] + 0.003, f"{tg[2]-tg[0]:.2f} × {tg[3]-tg[1]:.2f}", fontsize=7)
    fig.suptitle("Oblique impact: aluminium plate strikes the steel plate off-centre "
                 "(assumed geometry; paper Fig. 8)")
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def stress_figure(hist, probe, win, win1, path, title):
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.2), sharey=True)
    ts, tu = style.time_scale(max(h["time"][-1] for h in hist.values()))
    vs, vu = style.field_scale(f"{probe}.sxx")
    # The extended reference first, so that the other curves are drawn over its band.
    order = ["extended", "free", "silent"]
    for ax, prefix, sub in zip(axes, ("", "multi_"),
                               ("single velocity field (the paper's MPM)",
                                "multi-velocity-field contact")):
        for bc in order:
            look, label = STYLE[bc]
            h = hist[prefix + bc]
            ax.plot([t * ts for t in h["time"]], [s * vs for s in h[f"{probe}.sxx"]], label=label,
                    **look)
        # The windows' ends: vertical lines explained in the legend (no text over the curves).
        ax.axvline(win * ts, color="0.3", lw=0.9, ls=(0, (6, 2, 1, 2)), zorder=0,
                   label=f"end of the reflection-free window ({win * ts:.1f} {tu})")
        ax.axvline(win1 * ts, color="0.3", lw=0.9, ls=(0, (1.5, 1.5)), zorder=0,
                   label=f"end of the first-reflection window ({win1 * ts:.1f} {tu})")
        ax.set_xlabel(f"time ({tu})")
        ax.set_title(sub)
    axes[0].set_ylabel(rf"$\sigma_{{xx}}$ at {probe} ({vu})")
    fig.suptitle(title)
    fig.tight_layout()
    # The legend under the panels, where it covers no curve (the tight bounding box takes it in).
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="upper center", bbox_to_anchor=(0.5, 0.0), ncol=3)
    fig.savefig(path)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--cases", required=True)
    ap.add_argument("--bin", required=True)
    args = ap.parse_args()
    style.apply()
    cases = {bc: json.load(open(os.path.join(args.cases, f"{bc}.json"))) for bc in BCS}
    for bc in BCS:  # bodies from gmsh surfaces: their extent as built, from the run's summary
        built = {b["name"]: b["extent"]
                 for b in json.load(open(os.path.join(args.out, bc, "summary.json")))["bodies"]}
        for b in cases[bc]["bodies"]:
            b.setdefault("box", built[b["name"]])
    h = cases["extended"]["grid"]["cell"]
    probes = {p["name"]: p["at"] for p in cases["extended"]["probes"]}
    runs = [p + bc for p in ("", "multi_") for bc in BCS]
    files = {r: os.path.join(args.out, r, "history.csv") for r in runs}
    hist = {r: read(f) for r, f in files.items()}

    metrics = {"metric": "relative L2 ||s - s_ext|| / ||s_ext|| of sigma_xx over [0, window end]",
               "probes": probes, "window_s": {}, "window_reason": {}}
    for name, at in probes.items():
        t_refl, t_win, c, d = window(cases["extended"], at, h)
        t_win = min(t_win, cases["extended"]["time"]["end"])
        metrics["window_s"][name] = [0.0, t_win]
        metrics["window_reason"][name] = (
            f"the first wave reflected at the extended plate's far end reaches {name} after "
            f"{d:.4f} m of travel from the contact face (image point), {d:.4f}/{c:.1f} = "
            f"{t_refl*1e6:.2f} us; the window ends {MARGIN_CELLS} cells of travel earlier")
    metrics["first_reflection_window_s"] = {}
    for name, at in probes.items():
        t1, t_arr, tc = first_reflection_window(cases["silent"], at, h)
        metrics["first_reflection_window_s"][name] = [0.0, t1]
        metrics["window_reason"][name + "_first_reflection"] = (
            f"direct wave and the first reflection from the truncated plate's right side: it "
            f"reaches {name} at {t_arr*1e6:.2f} us, the contact lasts 2 d/c_d = {tc*1e6:.2f} us, "
            f"plus {MARGIN_CELLS} cells of travel")
    for prefix, key in (("", "single"), ("multi_", "multi")):
        m = {}
        for bc in ("silent", "free"):
            m[f"{bc}_vs_extended"] = {
                name: compare(args.bin, files[prefix + bc], files[prefix + "extended"],
                              f"{name}.sxx", 0.0, metrics["window_s"][name][1])
                for name in probes}
        for bc in ("silent", "free"):
            m[f"{bc}_vs_extended_first_reflection"] = {
                name: compare(args.bin, files[prefix + bc], files[prefix + "extended"],
                              f"{name}.sxx", 0.0, metrics["first_reflection_window_s"][name][1])
                for name in probes}
        if key == "single":
            metrics.update(m)  # the paper's contact: the headline numbers
        else:
            metrics["multi_velocity_contact"] = m
    metrics["contact"] = ("headline numbers: the paper's single velocity field; "
                          "multi_velocity_contact: the same runs with one field per body")
    summaries = {r: json.load(open(os.path.join(args.out, r, "summary.json"))) for r in runs}
    metrics["wall_seconds"] = {r: s["wall_seconds"] for r, s in summaries.items()}
    metrics["particle_updates_per_second"] = {r: s["particle_updates_per_second"]
                                              for r, s in summaries.items()}
    metrics["particles"] = {r: s["particles"] for r, s in summaries.items()}
    metrics["peak_sxx_MPa"] = {r: {n: min(hist[r][f"{n}.sxx"]) / 1e6 for n in probes}
                               for r in runs}
    with open(os.path.join(args.out, "metrics.json"), "w") as f:
        json.dump(metrics, f, indent=2)
        f.write("\n")

    figure8(cases, probes, os.path.join(args.out, "figure8.png"))
    stress_figure(hist, "B", metrics["window_s"]["B"][1],
                  metrics["first_reflection_window_s"]["B"][1], os.path.join(args.out, "figure9.png"),
                  "Longitudinal stress at B (paper Fig. 9)")
    stress_figure(hist, "C", metrics["window_s"]["C"][1],
                  metrics["first_reflection_window_s"]["C"][1], os.path.join(args.out, "figure10.png"),
                  "Longitudinal stress at C (paper Fig. 10)")

    print(f"{'':44s}{'B':>10s}{'C':>10s}")
    for label, m in (("single", metrics), ("multi", metrics["multi_velocity_contact"])):
        for k in ("silent_vs_extended", "free_vs_extended", "silent_vs_extended_first_reflection",
                  "free_vs_extended_first_reflection"):
            print(f"{label + ' ' + k:44s}{m[k]['B']:10.4f}{m[k]['C']:10.4f}")
    print("windows (us):", {n: round(w[1] * 1e6, 2) for n, w in metrics["window_s"].items()},
          "first reflection:",
          {n: round(w[1] * 1e6, 2) for n, w in metrics["first_reflection_window_s"].items()})


if __name__ == "__main__":
    main()
