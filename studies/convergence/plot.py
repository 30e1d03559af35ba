"""Figures 12-13 and metrics.json of the convergence study (called by studies/convergence/run).

Reads OUTDIR/h_<cell>/ and OUTDIR/ppc_<n>/ (history.csv, summary.json). Differences between
successive refinements are relative L2 norms of sigma_xx at D over the whole run,
||s_coarse - s_fine|| / ||s_fine||, with the finer history interpolated onto the coarser one's
times (`silentmpm compare`, the implementation the tests use). The observed order p solves
e_12 / e_23 = (h1^p - h2^p) / (h2^p - h3^p) for three successive levels (h = the cell size, or
the particle spacing h/sqrt(ppc) for the particles-per-cell series), the model being
s_h = s + C h^p.
"""
import argparse
import json
import math
import os

import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
import style  # noqa: E402
from history import compare, read_history as read  # noqa: E402

import matplotlib.pyplot as plt  # noqa: E402

CELLS = ["0.01", "0.005", "0.002"]
EXTRA_CELLS = ["0.001"]  # a further level beyond the paper's, when present
PPC = [1, 4, 9]
SMOOTH_S = 5e-6  # moving-average width of the smoothed differences


def smoothed_difference(fa, fb, width):
    """Relative L2 of the two sigma_xx(t) histories after a moving average over `width` seconds
    (both on a common 0.05 us grid): the part of the difference that is not grid-frequency
    ringing."""
    a, b = read(fa), read(fb)
    t1 = min(a["time"][-1], b["time"][-1])
    t = np.arange(0.0, t1, 5e-8)
    ya = np.interp(t, a["time"], a["D.sxx"], left=0.0)
    yb = np.interp(t, b["time"], b["D.sxx"], left=0.0)
    n = max(1, int(round(width / 5e-8)))
    k = np.ones(n) / n
    sa, sb = np.convolve(ya, k, mode="same"), np.convolve(yb, k, mode="same")
    return float(np.linalg.norm(sa - sb) / np.linalg.norm(sb))


def observed_order(h, e):
    """p with e[0]/e[1] = (h0^p - h1^p)/(h1^p - h2^p), by bisection; None if no root."""
    ratio = e[0] / e[1]

    def f(p):
        return (h[0] ** p - h[1] ** p) / (h[1] ** p - h[2] ** p) - ratio

    lo, hi = 1e-3, 8.0
    if f(lo) * f(hi) > 0:
        return None
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if f(lo) * f(mid) <= 0:
            hi = mid
        else:
            lo = mid
    return 0.5 * (lo + hi)


def series(out, binary, runs, sizes):
    files = [os.path.join(out, r, "history.csv") for r in runs]
    diffs = []
    for k in range(len(runs) - 1):
        diffs.append({"coarse": runs[k], "fine": runs[k + 1],
                      "relative_l2": compare(binary, files[k], files[k + 1], "D.sxx"),
                      "relative_l2_smoothed": smoothed_difference(files[k], files[k + 1],
                                                                  SMOOTH_S)})
    m = {"runs": runs, "spacing_m": sizes, "successive_differences": diffs}
    orders = []
    for k in range(len(runs) - 2):
        p = observed_order(sizes[k:k + 3], [diffs[k]["relative_l2"], diffs[k + 1]["relative_l2"]])
        orders.append({"levels": runs[k:k + 3], "order": p})
    m["observed_order"] = orders
    m["observed_order_smoothed"] = [
        {"levels": runs[k:k + 3],
         "order": observed_order(sizes[k:k + 3], [diffs[k]["relative_l2_smoothed"],
                                                  diffs[k + 1]["relative_l2_smoothed"]])}
        for k in range(len(runs) - 2)]
    m["differences_decrease"] = all(diffs[k + 1]["relative_l2"] < diffs[k]["relative_l2"]
                                    for k in range(len(diffs) - 1))
    runs_info = {}
    for r in runs:
        s = json.load(open(os.path.join(out, r, "summary.json")))
        runs_info[r] = {"particles": s["particles"], "steps": s["steps"], "dt": s["dt"],
                        "wall_seconds": s["wall_seconds"],
                        "particle_updates_per_second": s["particle_updates_per_second"],
                        "energy_relative_imbalance": s["energy"].get("relative_imbalance")}
    m["runs_info"] = runs_info
    return m


def figure(out, runs, labels, path, title):
    style.apply()
    fig, ax = plt.subplots(figsize=(8, 4.5))
    # Coarse to fine: each level its colour of style.COLOURS and its own dashes (grey print).
    c = style.COLOURS
    styles = [(c[1], "--"), (c[2], "-."), (c[0], "-"), (c[6], ":")]
    hs = [read(os.path.join(out, r, "history.csv")) for r in runs]
    ts, tu = style.time_scale(max(h["time"][-1] for h in hs))
    vs, vu = style.field_scale("D.sxx")
    for h, lab, (col, ls) in zip(hs, labels, styles):
        ax.plot([t * ts for t in h["time"]], [s * vs for s in h["D.sxx"]], color=col, ls=ls,
                label=lab)
    ax.set_xlabel(f"time ({tu})")
    ax.set_ylabel(rf"$\sigma_{{xx}}$ at D ({vu})")
    ax.set_title(title)
    ax.legend(loc="best")
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--bin", required=True)
    args = ap.parse_args()
    cells = CELLS + [c for c in EXTRA_CELLS if os.path.exists(os.path.join(args.out, f"h_{c}",
                                                                           "summary.json"))]
    cell_runs = [f"h_{c}" for c in cells]
    ppc_runs = ["h_0.01", "ppc_4", "ppc_9"]
    metrics = {
        "metric": "relative L2 ||s_coarse - s_fine|| / ||s_fine|| of sigma_xx at D over the run",
        "metric_smoothed": "the same after a 5 us moving average of both histories",
        "cell_size": series(args.out, args.bin, cell_runs, [float(c) for c in cells]),
        "particles_per_cell": series(args.out, args.bin, ppc_runs,
                                     [0.01 / math.sqrt(n) for n in PPC]),
    }
    metrics["particles_per_cell"]["particles_per_cell"] = PPC
    with open(os.path.join(args.out, "metrics.json"), "w") as f:
        json.dump(metrics, f, indent=2)
        f.write("\n")
    figure(args.out, cell_runs, [f"cell {c} m, 1 particle per cell" for c in cells],
           os.path.join(args.out, "figure12.png"),
           "Stress at D for different cell sizes (paper Fig. 12)")
    figure(args.out, ppc_runs, [f"cell 0.01 m, {n} particle{'s' if n > 1 else ''} per cell"
                                for n in PPC],
           os.path.join(args.out, "figure13.png"),
           "Stress at D for different particles per cell (paper Fig. 13)")
    for key in ("cell_size", "particles_per_cell"):
        m = metrics[key]
        print(key)
        for d in m["successive_differences"]:
            print(f"  {d['coarse']:>8s} vs {d['fine']:<8s} {d['relative_l2']:.4f}   smoothed "
                  f"{d['relative_l2_smoothed']:.4f}")
        for o in m["observed_order"]:
            p = o["order"]
            print(f"  observed order {'-'.join(o['levels'])}: {p:.2f}" if p is not None else
                  f"  observed order {'-'.join(o['levels'])}: no root (differences not decreasing)")
        for o in m["observed_order_smoothed"]:
            p = o["order"]
            print(f"  observed order (smoothed) {'-'.join(o['levels'])}: "
                  + (f"{p:.2f}" if p is not None else "no root"))
        for r, i in m["runs_info"].items():
            print(f"  {r:8s} {i['particles']:7d} particles {i['steps']:6d} steps "
                  f"{i['wall_seconds']:7.2f} s {i['particle_updates_per_second']:.3g} updates/s")


if __name__ == "__main__":
    main()
