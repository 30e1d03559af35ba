#!/usr/bin/python3
"""Metrics and figures of the hybrid study: relative L2 differences of the probe histories against
the all-MPM extended runs, CPU time, wall time and peak memory of each run (best of the timing
runs), the hybrid's speed-up. Usage: metrics.py OUTDIR (the folder studies/hybrid/run wrote)."""
import csv
import json
import os
import sys

import numpy as np


def history(path):
    with open(path) as f:
        rows = list(csv.reader(f))
    head = rows[0]
    data = np.array([[float(v) for v in r] for r in rows[1:]])
    return {h: data[:, i] for i, h in enumerate(head)}


def rel_l2(a, b, col, t0=0.0, t1=np.inf):
    """Relative L2 of a[col] - b[col] over [t0, t1], b interpolated on a's times."""
    t = a["time"]
    m = (t >= t0) & (t <= t1)
    bb = np.interp(t[m], b["time"], b[col])
    return float(np.sqrt(np.sum((a[col][m] - bb) ** 2) / np.sum(bb ** 2)))


def repetitions(out, prefix):
    """Numbers k of the files OUTDIR/<prefix>_<k>.txt, sorted."""
    ks = []
    for f in os.listdir(out):
        if f.startswith(prefix + "_") and f.endswith(".txt"):
            tail = f[len(prefix) + 1:-4]
            if tail.isdigit():
                ks.append(int(tail))
    return sorted(ks)


def cpu(path):
    t = dict(line.split() for line in open(path) if line.strip())
    return float(t["user"]) + float(t["system"])


def timing(out, name):
    best = None
    for k in repetitions(out, "time_" + name):
        p = os.path.join(out, "time_%s_%d.txt" % (name, k))
        t = dict(line.split() for line in open(p) if line.strip())
        s = json.load(open(os.path.join(out, "time_%s_%d.summary.json" % (name, k))))
        rec = {"cpu_seconds": float(t["user"]) + float(t["system"]), "wall_seconds": float(t["wall"]),
               "step_wall_seconds": s["step_seconds"], "max_rss_mb": int(t["maxrss_kb"]) / 1024.0,
               "particles": s["particles"], "fem_dofs": s.get("dofs", 0), "steps": s["steps"]}
        if best is None or rec["cpu_seconds"] < best["cpu_seconds"]:
            best = rec
    # Fixed cost: the best of the one-step runs; the steps' CPU time is the difference.
    setup = None
    for k in repetitions(out, "setup_" + name):
        c = cpu(os.path.join(out, "setup_%s_%d.txt" % (name, k)))
        setup = c if setup is None else min(setup, c)
    if best is not None and setup is not None:
        best["setup_cpu_seconds"] = setup
        best["steps_cpu_seconds"] = best["cpu_seconds"] - setup
    return best


def main(out):
    film = ["film_extended", "film_silent", "film_hybrid_fixed", "film_hybrid_dashpot",
            "film_hybrid_graded_fixed", "film_hybrid_coarse_fixed", "film_extended_elastic",
            "film_hybrid_fixed_elastic", "film_hybrid_graded_fixed_elastic",
            "film_hybrid_coarse_fixed_elastic"]
    pulse = ["pulse_extended", "pulse_silent", "pulse_hybrid_extended", "pulse_hybrid_dashpot"]
    H = {n: history(os.path.join(out, n, "history.csv")) for n in film + pulse}
    m = {"reference": {"film": "film_extended (all-MPM, 15 um substrate, bottom fixed)",
                       "film_elastic": "film_extended_elastic",
                       "pulse": "pulse_extended (all-MPM plate extended to 150 mm)"},
         # The extended plate's free end (x = 150 mm) sends its reflection back to A (x = 40 mm)
         # at (2 * 150 - 40) mm / c_d = 43.9 us: the reference holds until then. The film's
         # extended substrate (15 um) holds to 3.25 ns, past the end of the runs (3.2 ns).
         "window": {"film": [0.0, 3.2e-9], "pulse": [0.0, 43e-6]},
         "runs": {}}
    for n in film + pulse:
        ref = ("film_extended_elastic" if n.endswith("_elastic") else "film_extended") \
            if n.startswith("film") else "pulse_extended"
        cols = ["E.syy", "F.syy", "E.J2", "F.J2", "E.sxx"] if n.startswith("film") else \
            ["A.sxx", "A.syy"]
        r = {"reference": ref}
        if n != ref:
            w = m["window"]["film" if n.startswith("film") else "pulse"]
            r["rel_l2"] = {c: rel_l2(H[n], H[ref], c, w[0], w[1]) for c in cols}
        r["timing"] = timing(out, n)
        s = json.load(open(os.path.join(out, n, "summary.json")))
        r["energy_relative_imbalance"] = s["energy"]["relative_imbalance"]
        m["runs"][n] = r
    # Process start alone (silentmpm --help: the shared libraries), best of the repetitions.
    starts = [cpu(os.path.join(out, "start_%d.txt" % k)) for k in repetitions(out, "start")]
    start = min(starts) if starts else None
    m["process_start_cpu_seconds"] = start
    sp = {}
    # Silent 5 um all-MPM run: its CPU time against the extended one, for scale.
    m["runs"]["film_silent"]["cpu_ratio_extended_over_this"] = (
        m["runs"]["film_extended"]["timing"]["cpu_seconds"] / m["runs"]["film_silent"]["timing"]["cpu_seconds"]
        if m["runs"]["film_silent"]["timing"] and m["runs"]["film_extended"]["timing"] else None)
    for hyb, ref in [("film_hybrid_fixed", "film_extended"), ("film_hybrid_dashpot", "film_extended"),
                     ("film_hybrid_graded_fixed", "film_extended"),
                     ("film_hybrid_coarse_fixed", "film_extended"),
                     ("film_hybrid_fixed_elastic", "film_extended_elastic"),
                     ("film_hybrid_graded_fixed_elastic", "film_extended_elastic"),
                     ("film_hybrid_coarse_fixed_elastic", "film_extended_elastic"),
                     ("pulse_hybrid_extended", "pulse_extended"), ("pulse_hybrid_dashpot", "pulse_extended")]:
        a, b = m["runs"][hyb]["timing"], m["runs"][ref]["timing"]
        if a and b:
            sp[hyb] = {"cpu_speedup": b["cpu_seconds"] / a["cpu_seconds"],
                       "steps_cpu_speedup": b.get("steps_cpu_seconds", 0) / max(a.get("steps_cpu_seconds", 1e-9), 1e-9),
                       "step_wall_speedup": b["step_wall_seconds"] / a["step_wall_seconds"],
                       "memory_ratio": a["max_rss_mb"] / b["max_rss_mb"]}
            if start is not None:  # the CPU time after the process start, which both pay alike
                sp[hyb]["cpu_after_start_speedup"] = (b["cpu_seconds"] - start) / (a["cpu_seconds"] - start)
    m["speedup_vs_all_mpm"] = sp
    with open(os.path.join(out, "metrics.json"), "w") as f:
        json.dump(m, f, indent=2)
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(1, 2, figsize=(11, 4))
        for n, st in [("film_extended", "k-"), ("film_silent", "b--"), ("film_hybrid_fixed", "r-."),
                      ("film_hybrid_dashpot", "g:"), ("film_hybrid_coarse_fixed", "m--")]:
            for a, p in zip(ax, "EF"):
                a.plot(H[n]["time"] * 1e9, H[n][p + ".syy"] / 1e9, st, label=n)
        for a, p in zip(ax, "EF"):
            a.set_xlabel("t (ns)"); a.set_ylabel("sigma_yy at %s (GPa)" % p); a.legend(fontsize=7)
        fig.tight_layout(); fig.savefig(os.path.join(out, "hybrid_film.png"), dpi=120)
        fig, ax = plt.subplots(1, 2, figsize=(11, 4))
        for n, st in [("pulse_extended", "k-"), ("pulse_silent", "b--"), ("pulse_hybrid_extended", "r-."),
                      ("pulse_hybrid_dashpot", "g:")]:
            for a, c in zip(ax, ["A.sxx", "A.syy"]):
                a.plot(H[n]["time"] * 1e6, H[n][c] / 1e6, st, label=n)
        for a, c in zip(ax, ["A.sxx", "A.syy"]):
            a.set_xlabel("t (us)"); a.set_ylabel(c + " (MPa)"); a.legend(fontsize=7)
        fig.tight_layout(); fig.savefig(os.path.join(out, "hybrid_pulse.png"), dpi=120)
    except ImportError:
        pass
    print(json.dumps(sp, indent=2))


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "out"))
