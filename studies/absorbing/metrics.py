"""Table and figure of studies/absorbing: reflection amplitude against the angle for each
boundary and method, with the LK closed form (docs/physics.md section 4.1) beside them.

    /usr/bin/python3 studies/absorbing/metrics.py OUTDIR

Reads OUTDIR/<fem|mpm>_<lk|kv|damping|rayleigh|pml|pml_r5>/metrics[_mpm].json (written by `oblique`), writes
OUTDIR/metrics.json and OUTDIR/reflection_vs_angle.png and prints the tables: the same-type
amplitude (|R_PP| for an incident P wave, |R_SS| for SV), the converted one (|R_PS|, |R_SP|), and
per boundary the largest amplitude of either type up to 80 degrees and beyond.
"""
import json
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
import style  # noqa: E402

import matplotlib.pyplot as plt  # noqa: E402

BOUNDARIES = ["lk", "kv", "damping", "rayleigh", "pml"]
# Variants in metrics.json and the summary only: the PML with r0 5e-3.
EXTRA = ["pml_r5"]
NAMES = {"lk": "LK dashpots", "kv": "Kelvin–Voigt", "damping": "damping band",
         "rayleigh": "Rayleigh band", "pml": "PML"}
METHODS = {"fem": "FEM far field", "mpm": "MPM"}
# The reflected types: same-type and converted, per incident wave.
KEYS = {"P": ("R_PP", "R_PS"), "SV": ("R_SS", "R_SP")}
GOAL_ANGLE = 80.0  # the largest angle the goals name
FLOOR = 1e-4  # the figure's lowest amplitude


def read(out):
    """{"same"|"converted": {wave: {angle: {column: amplitude}}}}, column "<method>_<boundary>"
    or "lk_exact"."""
    table = {"same": {}, "converted": {}}
    for m in METHODS:
        for b in BOUNDARIES + EXTRA:
            f = os.path.join(out, f"{m}_{b}", "metrics.json" if m == "fem" else "metrics_mpm.json")
            if not os.path.exists(f):
                continue
            for r in json.load(open(f))["results"]:
                for kind, key in zip(("same", "converted"), KEYS[r["wave"]]):
                    row = table[kind].setdefault(r["wave"], {}).setdefault(r["angle_deg"], {})
                    row[f"{m}_{b}"] = r[key]
                    row["lk_exact"] = r[key + "_exact"]
    return table


def largest(table, col, lo, hi):
    """The largest amplitude of either type and wave at angles in [lo, hi], and where."""
    best = (-1.0, None, None)
    for kind in table.values():
        for wave, rows in kind.items():
            for a, row in rows.items():
                if lo <= float(a) <= hi and col in row and row[col] > best[0]:
                    best = (row[col], wave, float(a))
    return best


def main(out):
    table = read(out)
    json.dump(table, open(os.path.join(out, "metrics.json"), "w"), indent=2)
    cols = ["lk_exact"] + [f"{m}_{b}" for m in METHODS for b in BOUNDARIES]
    # One colour per boundary (style.COLOURS); FEM filled circles on dashed lines, MPM open squares
    # on dotted lines; the closed form a solid black line.
    look = {"lk_exact": dict(color="k", ls="-", label="LK closed form")}
    for k, b in enumerate(BOUNDARIES):
        look[f"fem_{b}"] = dict(color=style.COLOURS[k], ls="--", marker="o",
                                label=f"{METHODS['fem']}, {NAMES[b]}")
        look[f"mpm_{b}"] = dict(color=style.COLOURS[k], ls=":", marker="s", mfc="none",
                                label=f"{METHODS['mpm']}, {NAMES[b]}")
    style.apply()
    fig, axes = plt.subplots(2, 2, figsize=(11, 8), sharex=True)
    for row, kind in enumerate(("same", "converted")):
        for ax, wave in zip(axes[row], ["P", "SV"]):
            rows = table[kind].get(wave, {})
            angles = sorted(rows, key=float)
            key = KEYS[wave][row]
            print(f"{kind} |{key}|, incident {wave}: angle  " + "  ".join(f"{c:>11s}" for c in cols))
            for a in angles:
                print(f"{wave}: {float(a):5.0f}  " + "  ".join(
                    f"{rows[a][c]:11.4f}" if c in rows[a] else f"{'-':>11s}" for c in cols))
            for c in cols:
                # A log axis from 1e-4: the amplitudes that matter run from 1e-3 to 1; below it
                # (a converted wave at normal incidence, 1e-16-1e-6, zero in the closed form)
                # the points are left out.
                ys = [(float(a), rows[a][c]) for a in angles if c in rows[a] and rows[a][c] >= FLOOR]
                if ys:
                    ax.plot([y[0] for y in ys], [y[1] for y in ys], ms=4, **look[c])
            ax.set_yscale("log")
            ax.set_ylim(FLOOR, 1.5)
            ax.set_title(f"incident {wave}: {'same-type' if row == 0 else 'converted'} reflection")
            if row == 1:
                ax.set_xlabel("angle from the normal (°)")
            ax.set_ylabel(f"$|R_{{{key[2:]}}}|$, reflected / incident amplitude")
    print(f"largest amplitude of either type, 0-{GOAL_ANGLE:.0f} degrees and beyond:")
    for c in cols[1:] + [f"{m}_{b}" for m in METHODS for b in EXTRA]:
        v, wave, a = largest(table, c, 0, GOAL_ANGLE)
        w, wave2, a2 = largest(table, c, GOAL_ANGLE + 1e-9, 90)
        if wave is None:
            continue
        beyond = f"; beyond: {w:.4f} ({wave2} {a2:.0f})" if wave2 else ""
        print(f"  {c:14s} {v:.4f} ({wave} {a:.0f}){beyond}")
    fig.suptitle("Absorbing boundaries on plane P and SV pulses: reflection against the angle")
    fig.tight_layout()
    # One legend for all panels, under them, where it covers no curve.
    handles, labels = axes[0][0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="upper center", bbox_to_anchor=(0.5, 0.0), ncol=3)
    fig.savefig(os.path.join(out, "reflection_vs_angle.png"))


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "studies/absorbing/out")
