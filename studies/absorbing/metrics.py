"""Table and figure of studies/absorbing: reflection amplitude against the angle for each
boundary and method, with the LK closed form (docs/physics.md section 4.1) beside them.

    /usr/bin/python3 studies/absorbing/metrics.py OUTDIR

Reads OUTDIR/<fem|mpm>_<lk|kv|damping|pml>/metrics[_mpm].json (written by `oblique`), writes
OUTDIR/metrics.json and OUTDIR/reflection_vs_angle.png and prints the table.
"""
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

BOUNDARIES = ["lk", "kv", "damping", "pml"]


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
                ax.plot([y[0] for y in ys], [y[1] for y in ys], "k-" if c == "lk_exact" else "o--",
                        label=c)
        ax.set_title(f"incident {wave}: same-type reflection amplitude")
        ax.set_xlabel("angle from the normal (deg)")
        ax.set_ylabel("|R_PP|" if wave == "P" else "|R_SS|")
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "reflection_vs_angle.png"), dpi=120)


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "studies/absorbing/out")
