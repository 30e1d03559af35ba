"""Table and figure of studies/absorbing: reflection amplitude against the angle for each
boundary and method, with the LK closed form (docs/physics.md section 4.1) beside them.

    /usr/bin/python3 studies/absorbing/metrics.py OUTDIR

Reads OUTDIR/<fem|mpm>_<lk|kv|damping|rayleigh|pml>/metrics[_mpm].json (written by `oblique`), writes
OUTDIR/metrics.json and OUTDIR/reflection_vs_angle.png and prints the table.
"""
import json
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
import style  # noqa: E402

import matplotlib.pyplot as plt  # noqa: E402

BOUNDARIES = ["lk", "kv", "damping", "rayleigh", "pml"]
NAMES = {"lk": "LK dashpots", "kv": "Kelvin–Voigt", "damping": "damping band",
         "rayleigh": "Rayleigh band", "pml": "PML"}
METHODS = {"fem": "FEM far field", "mpm": "MPM"}


def main(out):
    table = {}
    for m in ["fem", "mpm"]:
        for b in BOUNDARIES:
            f = os.path.join(out, f"{m}_{b}", "metrics.json" if m == "fem" else "metrics_mpm.json")
            if not os.path.exists(f):
                continue
            j = json.load(open(f))
            for r in j["results"]:
                key = "R_PP" if r["wave"] == "P" else "R_SS"
                table.setdefault(r["wave"], {}).setdefault(r["angle_deg"], {})[f"{m}_{b}"] = r[key]
                table[r["wave"]][r["angle_deg"]]["lk_exact"] = r[key + "_exact"]
    json.dump(table, open(os.path.join(out, "metrics.json"), "w"), indent=2)
    cols = ["lk_exact"] + [f"{m}_{b}" for m in ["fem", "mpm"] for b in BOUNDARIES]
    # One colour per boundary (style.COLOURS); FEM filled circles on dashed lines, MPM open squares
    # on dotted lines; the closed form a solid black line.
    look = {"lk_exact": dict(color="k", ls="-", label="LK closed form")}
    for k, b in enumerate(BOUNDARIES):
        look[f"fem_{b}"] = dict(color=style.COLOURS[k], ls="--", marker="o",
                                label=f"{METHODS['fem']}, {NAMES[b]}")
        look[f"mpm_{b}"] = dict(color=style.COLOURS[k], ls=":", marker="s", mfc="none",
                                label=f"{METHODS['mpm']}, {NAMES[b]}")
    style.apply()
    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    for ax, wave in zip(axes, ["P", "SV"]):
        rows = table.get(wave, {})
        angles = sorted(rows, key=float)
        print(f"{wave}: angle  " + "  ".join(f"{c:>11s}" for c in cols))
        for a in angles:
            print(f"{wave}: {float(a):5.0f}  " + "  ".join(
                f"{rows[a][c]:11.4f}" if c in rows[a] else f"{'-':>11s}" for c in cols))
        for c in cols:
            ys = [(float(a), rows[a][c]) for a in angles if c in rows[a]]
            if ys:
                ax.plot([y[0] for y in ys], [y[1] for y in ys], ms=5, **look[c])
        ax.set_title(f"incident {wave}: same-type reflection amplitude")
        ax.set_xlabel("angle from the normal (°)")
        ax.set_ylabel(("$|R_{PP}|$" if wave == "P" else "$|R_{SS}|$") + ", reflected / incident")
    fig.suptitle("Absorbing boundaries on plane P and SV pulses: reflection against the angle")
    fig.tight_layout()
    # One legend for both panels, under them, where it covers no curve.
    handles, labels = axes[0].get_legend_handles_labels()
    if not handles:
        handles, labels = axes[1].get_legend_handles_labels()
    fig.legend(handles, labels, loc="upper center", bbox_to_anchor=(0.5, 0.0), ncol=3)
    fig.savefig(os.path.join(out, "reflection_vs_angle.png"))


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "studies/absorbing/out")
