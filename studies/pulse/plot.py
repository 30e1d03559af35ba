"""Figures 5-7 and metrics.json of the pulse study (called by studies/pulse/run).

Reads OUTDIR/<load>_<treatment>/history.csv, plots the stress at A for the three right-side
treatments, and computes the relative L2 differences against the extended run with the same
implementation the tests use (`silentmpm compare`).
"""
import argparse
import json
import os

import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
import style  # noqa: E402
from history import compare, read_history as read  # noqa: E402

import matplotlib.pyplot as plt  # noqa: E402

# Curve looks: the MPM extended run is the reference, a wide light-grey band under the others; the
# FEM extended run is black dotted on top of it, the two truncated treatments of each method solid
# / dashed / dash-dot in colours of style.COLOURS (apart in grey print by their dashes too).
STYLE = {"free": dict(color=style.COLOURS[1], ls="--", lw=1.4, label="MPM, free boundary"),
         "silent": dict(color=style.COLOURS[0], ls="-", lw=1.4, label="MPM, silent boundary"),
         "extended": dict(color="0.72", ls="-", lw=3.6, zorder=1,
                          label="MPM, extended region (reference)"),
         "fem_dashpot": dict(color=style.COLOURS[2], ls="-.", lw=1.4, label="FEM, LK dashpots"),
         "fem_extended": dict(color=style.COLOURS[6], ls=":", lw=1.5, label="FEM, extended region")}
# All three figures alike: the same size and the same axes box, the legend outside on the right.
FIGSIZE = (8.6, 4.2)       # inches
AXES_BOX = [0.085, 0.12, 0.6, 0.8]  # left, bottom, width, height (figure fractions)
FIGURES = [("figure5.png", "compressive", "sxx", r"$\sigma_{xx}$ at A (MPa)",
            "Longitudinal stress at A, compressive pulse (paper Fig. 5)"),
           ("figure6.png", "compressive", "syy", r"$\sigma_{yy}$ at A (MPa)",
            "Lateral stress at A, compressive pulse (paper Fig. 6)"),
           ("figure7.png", "shear", "sxy", r"$\tau_{xy}$ at A (MPa)",
            "Shear stress at A, shear pulse (paper Fig. 7)")]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--study", required=True)
    ap.add_argument("--bin", required=True)
    args = ap.parse_args()
    study = json.load(open(args.study))
    probe = study["probe"]
    hist = {}
    fem = study.get("fem_treatments", [])
    for load in study["loads"]:
        for bc in study["treatments"] + fem:
            hist[(load, bc)] = os.path.join(args.out, f"{load}_{bc}", "history.csv")
    # FEM curves are drawn and compared when their runs exist (studies/pulse/run makes them).
    fem = [bc for bc in fem if all(os.path.exists(hist[(load, bc)]) for load in study["loads"])]

    metrics = {"probe": probe, "pulse": "sin^2-ramped, 200 MPa, 20 us, 2 us ramps",
               "metric": "relative L2 ||s - s_ext|| / ||s_ext|| of the component at A over the window"}
    for load, spec in study["loads"].items():
        t0, t1 = spec["window"]
        m = {"window_s": [t0, t1], "window_reason": spec["window_reason"]}
        for k, comp in enumerate(spec["components"]):
            col = f"{probe}.{comp}"
            ext = hist[(load, "extended")]
            entry = {bc: compare(args.bin, hist[(load, bc)], ext, col, t0, t1)
                     for bc in ("silent", "free")}
            vals = {"silent_vs_extended": entry["silent"], "free_vs_extended": entry["free"]}
            if len(fem) == 2:
                # FEM with dashpots against the FEM extended plate, and MPM against FEM
                # (||mpm - fem|| / ||fem||): extended vs extended, silent layer vs dashpots.
                vals["fem_dashpot_vs_fem_extended"] = compare(
                    args.bin, hist[(load, "fem_dashpot")], hist[(load, "fem_extended")], col, t0, t1)
                vals["mpm_vs_fem"] = {
                    "extended": compare(args.bin, ext, hist[(load, "fem_extended")], col, t0, t1),
                    "silent_vs_dashpot": compare(args.bin, hist[(load, "silent")],
                                                 hist[(load, "fem_dashpot")], col, t0, t1)}
            if k == 0:
                m["component"] = comp
                m.update(vals)
            else:
                m[comp] = vals
        summaries = {bc: json.load(open(os.path.join(args.out, f"{load}_{bc}", "summary.json")))
                     for bc in study["treatments"] + fem}
        m["wall_seconds"] = {bc: s["wall_seconds"] for bc, s in summaries.items()}
        m["particle_updates_per_second"] = {bc: s["particle_updates_per_second"]
                                            for bc, s in summaries.items() if bc not in fem}
        if fem:
            m["fem_dof_updates_per_second"] = {bc: summaries[bc]["dof_updates_per_second"] for bc in fem}
        metrics[load] = m

    style.apply()
    # The reference first, so that the other curves are drawn over its band.
    order = ["extended"] + [bc for bc in study["treatments"] + fem if bc != "extended"]
    for fname, load, comp, ylabel, title in FIGURES:
        fig = plt.figure(figsize=FIGSIZE)
        ax = fig.add_axes(AXES_BOX)
        hs = {bc: read(hist[(load, bc)]) for bc in order}
        ts, tu = style.time_scale(max(h["time"][-1] for h in hs.values()))
        vs, _ = style.field_scale(f"{probe}.{comp}")
        for bc in order:
            h = hs[bc]
            ax.plot([t * ts for t in h["time"]], [v * vs for v in h[f"{probe}.{comp}"]], **STYLE[bc])
        # The end of the window: a vertical line, explained in the legend (no text over the data).
        t1 = study["loads"][load]["window"][1]
        ax.axvline(t1 * ts, color="0.3", lw=0.9, ls=(0, (6, 2, 1, 2)), zorder=0,
                   label=f"end of the extended run's\nreflection-free window ({t1 * ts:.1f} {tu})")
        ax.set_xlabel(f"time ({tu})")
        ax.set_ylabel(ylabel)
        ax.set_title(title)
        ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0)
        # Fixed size (no tight bounding box): Figs. 5-7 have the same size and the same axes box.
        with plt.rc_context({"savefig.bbox": "standard"}):
            fig.savefig(os.path.join(args.out, fname))
        plt.close(fig)

    with open(os.path.join(args.out, "metrics.json"), "w") as f:
        json.dump(metrics, f, indent=2)
        f.write("\n")

    print(f"\npulse study: figures and metrics in {args.out}")
    print(f"{'load':<12} {'component':<10} {'window (us)':<14} {'silent_vs_ext':>14} {'free_vs_ext':>12}")
    for load, spec in study["loads"].items():
        m = metrics[load]
        w = f"0-{m['window_s'][1] * 1e6:.1f}"
        print(f"{load:<12} {m['component']:<10} {w:<14} {m['silent_vs_extended']:>14.4f} "
              f"{m['free_vs_extended']:>12.4f}")
        for comp in spec["components"][1:]:
            print(f"{'':<12} {comp:<10} {w:<14} {m[comp]['silent_vs_extended']:>14.4f} "
                  f"{m[comp]['free_vs_extended']:>12.4f}")
        if fem:
            for comp in spec["components"]:
                v = m if comp == m["component"] else m[comp]
                print(f"{'':<12} {comp:<10} FEM dashpot vs FEM extended {v['fem_dashpot_vs_fem_extended']:.4f}; "
                      f"MPM vs FEM: extended {v['mpm_vs_fem']['extended']:.4f}, "
                      f"silent vs dashpot {v['mpm_vs_fem']['silent_vs_dashpot']:.4f}")


if __name__ == "__main__":
    main()
