#!/usr/bin/env python3
"""Gathers the shape comparison of studies/shapes/run into OUTDIR/metrics.json and shapes.png and
prints the table (usage: metrics.py OUTDIR)."""
import json
import os
import re
import sys

SHAPES = ["bilinear", "gimp", "bspline"]
LABEL = {"bilinear": "bilinear", "gimp": "uGIMP", "bspline": "quadratic B-spline"}


def convergence(out, shape):
    m = json.load(open(os.path.join(out, f"convergence_{shape}", "metrics.json")))
    cells = [d["relative_l2"] for d in m["cell_size"]["successive_differences"]]
    ppc = [d["relative_l2"] for d in m["particles_per_cell"]["successive_differences"]]
    imb = []
    for run in ("h_0.01", "h_0.005", "h_0.002", "ppc_4", "ppc_9"):
        s = json.load(open(os.path.join(out, f"convergence_{shape}", run, "summary.json")))
        imb.append(abs(s["energy"]["relative_imbalance"]))
    return {"cells_0.01_0.005": cells[0], "cells_0.005_0.002": cells[1],
            "ppc_1_4": ppc[0], "ppc_4_9": ppc[1], "worst_relative_imbalance": max(imb)}


def column(out):
    r = {}
    pat = re.compile(r"\[(.+)\] reflected energy / incident = ([0-9.eE+-]+)")
    for line in open(os.path.join(out, "column.txt")):
        m = pat.search(line)
        if m:
            r[m.group(1)] = float(m.group(2))
    return r


def oblique(out, shape):
    p = os.path.join(out, f"oblique_{shape}", "metrics_mpm.json")
    if not os.path.exists(p):
        return None
    res = {}
    for e in json.load(open(p))["results"]:
        w, a = e["wave"], int(round(e["angle_deg"]))
        if w == "P":
            res[f"P{a}"] = {"R_PP": e["R_PP"], "R_PP_exact": e["R_PP_exact"], "R_PS": e["R_PS"],
                            "R_PS_exact": e["R_PS_exact"]}
        else:
            res[f"SV{a}"] = {"R_SS": e["R_SS"], "R_SS_exact": e["R_SS_exact"], "R_SP": e["R_SP"],
                             "R_SP_exact": e["R_SP_exact"]}
    return res


def bench(out):
    r = {}
    for line in open(os.path.join(out, "bench.txt")):
        f = line.split()  # particles, boundary, threads, steps, updates/s, shape[, bytes, GB/s, %]
        if len(f) >= 6 and f[0].isdigit() and f[5] in SHAPES:
            r.setdefault(f[5], {})[f"{f[0]} {f[1]} {f[2]}t"] = float(f[4])
    return r


def main():
    out = sys.argv[1]
    col = column(out)
    m = {"shapes": {}}
    b = bench(out)
    for s in SHAPES:
        tag = {"bilinear": "default", "gimp": "gimp", "bspline": "bspline"}[s]
        m["shapes"][s] = {
            "convergence": convergence(out, s),
            "column_P_1ppc": col.get("P default 1ppc" if s == "bilinear" else f"P {tag} 1ppc"),
            "column_P_4ppc": col.get("P default 4ppc" if s == "bilinear" else f"P {tag} 4ppc"),
            "column_P_edge": col.get(f"P {s} 1ppc edge" if s != "gimp" else "P gimp 4ppc edge"),
            "oblique": oblique(out, s),
            "bench_updates_per_second": b.get(s),
        }
    m["column_all"] = col
    with open(os.path.join(out, "metrics.json"), "w") as f:
        json.dump(m, f, indent=2)
        f.write("\n")
    hdr = ("shape", "conv h .01/.005", "h .005/.002", "ppc 1/4", "ppc 4/9", "|imbal|",
           "col P 1ppc", "col P 4ppc", "P30 RPP", "P45 RPP", "SV30 RSS", "1e5 free 1t")
    print(" | ".join(hdr))
    for s in SHAPES:
        x = m["shapes"][s]
        c = x["convergence"]
        o = x["oblique"] or {}
        g = lambda k, q: (o.get(k) or {}).get(q)
        fmt = lambda v: "-" if v is None else f"{v:.3g}"
        bb = (x["bench_updates_per_second"] or {})
        rate = next((v for k, v in bb.items() if k.endswith("free 1t") and k.startswith("99856")), None)
        row = [LABEL[s], fmt(c["cells_0.01_0.005"]), fmt(c["cells_0.005_0.002"]), fmt(c["ppc_1_4"]),
               fmt(c["ppc_4_9"]), fmt(c["worst_relative_imbalance"]), fmt(x["column_P_1ppc"]),
               fmt(x["column_P_4ppc"]), fmt(g("P30", "R_PP")), fmt(g("P45", "R_PP")),
               fmt(g("SV30", "R_SS")), fmt(rate)]
        print(" | ".join(row))
    try:
        sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
        import style
        import matplotlib.pyplot as plt
        style.apply()
        # Bars: colours of style.COLOURS and a hatch each (apart in grey print); each panel's
        # legend under it, where it covers no bar.
        hatch = ["", "//", "..", "xx"]
        bar = lambda k: dict(color=style.COLOURS[k], hatch=hatch[k], edgecolor="white", lw=0)  # noqa: E731
        fig, ax = plt.subplots(1, 3, figsize=(13, 4))
        xs = range(len(SHAPES))
        for k, key in enumerate(["cells_0.01_0.005", "cells_0.005_0.002", "ppc_1_4", "ppc_4_9"]):
            lab = {"cells_0.01_0.005": "cells 0.01 → 0.005 m", "cells_0.005_0.002": "cells 0.005 → 0.002 m",
                   "ppc_1_4": "1 → 4 particles per cell", "ppc_4_9": "4 → 9 particles per cell"}[key]
            ax[0].bar([i + 0.2 * k for i in xs], [m["shapes"][s]["convergence"][key] for s in SHAPES],
                      width=0.2, label=lab, **bar(k))
        ax[0].set_xticks([i + 0.3 for i in xs], [LABEL[s] for s in SHAPES])
        ax[0].set_title("convergence (plates, σxx at D)")
        ax[0].set_ylabel("relative L2 difference of successive runs")
        for k, key in enumerate(["column_P_1ppc", "column_P_4ppc", "column_P_edge"]):
            lab = {"column_P_1ppc": "P wave, 1 ppc", "column_P_4ppc": "P wave, 4 ppc",
                   "column_P_edge": "P wave, end on the grid's edge"}[key]
            ax[1].bar([i + 0.25 * k for i in xs], [m["shapes"][s][key] or 0 for s in SHAPES],
                      width=0.25, label=lab, **bar(k))
        ax[1].set_yscale("log")
        ax[1].set_xticks([i + 0.25 for i in xs], [LABEL[s] for s in SHAPES])
        ax[1].set_title("column: silent layer at normal incidence")
        ax[1].set_ylabel("reflected / incident energy")
        for k, key in enumerate(["P30", "P45", "SV30", "SV45"]):
            q = "R_PP" if key.startswith("P") else "R_SS"
            vals = [((m["shapes"][s]["oblique"] or {}).get(key) or {}).get(q) or 0 for s in SHAPES]
            wave, angle = ("P", key[1:]) if key.startswith("P") else ("SV", key[2:])
            ax[2].bar([i + 0.2 * k for i in xs], vals, width=0.2,
                      label=f"{wave} at {angle}°: $|R_{{{q[2:]}}}|$", **bar(k))
        ex = ((m["shapes"]["bilinear"]["oblique"] or {}).get("P30") or {}).get("R_PP_exact")
        if ex:
            ax[2].axhline(ex, color="k", lw=0.8, ls="--", label="closed form, P at 30°")
        ax[2].set_xticks([i + 0.3 for i in xs], [LABEL[s] for s in SHAPES])
        ax[2].set_title("oblique incidence on the silent layer (MPM)")
        ax[2].set_ylabel("reflected / incident amplitude")
        for a in ax:
            a.grid(axis="x", visible=False)
        fig.suptitle("Grid shape functions compared: convergence and the silent layer's reflection")
        fig.tight_layout()
        for a in ax:
            a.legend(loc="upper center", bbox_to_anchor=(0.5, -0.1), ncol=2)
        fig.savefig(os.path.join(out, "shapes.png"))
    except ImportError:
        print("shapes: matplotlib not found; no figure", file=sys.stderr)


if __name__ == "__main__":
    main()
