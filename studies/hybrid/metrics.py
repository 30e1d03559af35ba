#!/usr/bin/python3
"""Metrics and figures of the hybrid study: relative L2 differences of the probe histories against
the all-MPM extended runs, each film run's error against the all-MPM extended run at half the cell
size, CPU time, wall time and peak memory of each run (best of the timing runs), the hybrid's
speed-up, and the figures of build/bench_hybrid (step loops in one process). Usage: metrics.py OUTDIR (the folder studies/hybrid/run wrote)."""
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


def interface_l2(a, b, field="syy", t0=0.0, t1=np.inf, n=21):
    """Relative L2 of the probe along the W-Si interface (I_00 ... I_20), all points together."""
    t = a["time"]
    m = (t >= t0) & (t <= t1)
    num = den = 0.0
    for k in range(n):
        c = "I_%02d.%s" % (k, field)
        bb = np.interp(t[m], b["time"], b[c])
        num += np.sum((a[c][m] - bb) ** 2)
        den += np.sum(bb ** 2)
    return float(np.sqrt(num / den))


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
            "film_hybrid_graded_fixed", "film_hybrid_coarse_fixed", "film_hybrid_unstructured_fixed",
            "film_hybrid_unstructured_1um_fixed", "film_extended_30um",
            "film_hybrid_unstructured_30um_fixed", "film_extended_elastic",
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
    m["reference"]["film_30um"] = "film_extended_30um (all-MPM, 30 um substrate, to 6.4 ns)"
    m["window"]["film_30um"] = [0.0, 6.4e-9]
    for n in film + pulse:
        ref = ("film_extended_elastic" if n.endswith("_elastic") else
               "film_extended_30um" if "30um" in n else "film_extended") \
            if n.startswith("film") else "pulse_extended"
        cols = ["E.syy", "F.syy", "E.J2", "F.J2", "E.sxx"] if n.startswith("film") else \
            ["A.sxx", "A.syy"]
        r = {"reference": ref}
        if n != ref:
            w = m["window"]["film_30um" if "30um" in n else "film" if n.startswith("film") else "pulse"]
            r["rel_l2"] = {c: rel_l2(H[n], H[ref], c, w[0], w[1]) for c in cols}
            if "I_00.syy" in H[n] and "I_00.syy" in H[ref]:  # the probe along the W-Si interface
                r["rel_l2"]["I.syy"] = interface_l2(H[n], H[ref], "syy", w[0], w[1])
                r["rel_l2"]["I.sxy"] = interface_l2(H[n], H[ref], "sxy", w[0], w[1])
        r["timing"] = timing(out, n)
        s = json.load(open(os.path.join(out, n, "summary.json")))
        r["energy_relative_imbalance"] = s["energy"]["relative_imbalance"]
        m["runs"][n] = r
    # Accuracy: each MUSL film run's error, its difference from the all-MPM extended run at half
    # the cell size (0.05 um), against the extended run's own error. Equal accuracy: a hybrid's
    # error within 5 % (relative) of the extended run's at every probe quantity.
    fine_dir = os.path.join(out, "film_extended_fine")
    if os.path.exists(os.path.join(fine_dir, "history.csv")):
        fine = history(os.path.join(fine_dir, "history.csv"))
        w = m["window"]["film"]
        cols = ["E.syy", "F.syy", "E.J2", "F.J2", "E.sxx"]
        err = {n: {c: rel_l2(H[n], fine, c, w[0], w[1]) for c in cols}
               for n in film if not n.endswith("_elastic") and "30um" not in n}
        acc = {"yardstick": "film_extended at 0.05 um cells, dt 1.6 ps (70 000 particles)",
               "error_vs_fine": err, "error_ratio_to_extended": {}, "equal_accuracy": {}}
        # The 30 um pair over [0, 6.4 ns] against the 30 um run at 0.05 um.
        fine30_dir = os.path.join(out, "film_extended_30um_fine")
        refs = {n: "film_extended" for n in err}
        if os.path.exists(os.path.join(fine30_dir, "history.csv")):
            fine30 = history(os.path.join(fine30_dir, "history.csv"))
            w30 = m["window"]["film_30um"]
            for n in ("film_extended_30um", "film_hybrid_unstructured_30um_fixed"):
                err[n] = {c: rel_l2(H[n], fine30, c, w30[0], w30[1]) for c in cols}
                refs[n] = "film_extended_30um"
            acc["yardstick_30um"] = "film_extended_30um at 0.05 um cells, dt 1.6 ps, over [0, 6.4 ns]"
        for n in err:
            ratio = {c: err[n][c] / err[refs[n]][c] for c in cols}
            acc["error_ratio_to_extended"][n] = ratio
            acc["equal_accuracy"][n] = bool(all(abs(r - 1) <= 0.05 for r in ratio.values()))
        m["accuracy_vs_fine"] = acc
    # The hybrid benchmark (build/bench_hybrid): step loops in one process, process CPU clock.
    bj = os.path.join(out, "bench_hybrid.json")
    if os.path.exists(bj):
        m["benchmark"] = json.load(open(bj))
    bj = os.path.join(out, "bench_hybrid_30um.json")
    if os.path.exists(bj):
        m["benchmark_30um"] = json.load(open(bj))
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
                     ("film_hybrid_unstructured_fixed", "film_extended"),
                     ("film_hybrid_unstructured_1um_fixed", "film_extended"),
                     ("film_hybrid_unstructured_30um_fixed", "film_extended_30um"),
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
                      ("film_hybrid_dashpot", "g:"), ("film_hybrid_coarse_fixed", "m--"),
                      ("film_hybrid_unstructured_fixed", "c-")]:
            for a, p in zip(ax, "EF"):
                a.plot(H[n]["time"] * 1e9, H[n][p + ".syy"] / 1e9, st, label=n)
        if "accuracy_vs_fine" in m:
            for a, p in zip(ax, "EF"):
                a.plot(fine["time"] * 1e9, fine[p + ".syy"] / 1e9, color="0.6", lw=0.8,
                       label="film_extended at 0.05 um (yardstick)")
        for a, p in zip(ax, "EF"):
            a.set_xlabel("t (ns)"); a.set_ylabel("sigma_yy at %s (GPa)" % p); a.legend(fontsize=7)
        fig.tight_layout(); fig.savefig(os.path.join(out, "hybrid_film.png"), dpi=120)
        # Cost against accuracy: step-loop CPU time (build/bench_hybrid where it ran, else the
        # timing runs' step wall time) and the error against the 0.05 um run.
        if "accuracy_vs_fine" in m:
            bc = m.get("benchmark", {}).get("cases", {})
            show = [("film_extended", "extended", "ks"), ("film_silent", "film_silent", "bv"),
                    ("film_hybrid_coarse_fixed", "film_hybrid_coarse_fixed", "m^"),
                    ("film_hybrid_unstructured_fixed", "film_hybrid_unstructured_fixed", "co"),
                    ("film_hybrid_unstructured_1um_fixed", "film_hybrid_unstructured_1um_fixed", "rD")]
            fig, ax = plt.subplots(1, 4, figsize=(14, 3.6), sharex=True)
            for a, c in zip(ax, ["E.syy", "F.syy", "E.J2", "F.J2"]):
                top = 0
                for n, bn, st in show:
                    if not m["runs"][n]["timing"]:
                        continue
                    t = bc[bn]["step_cpu_seconds_min"] if bn in bc else m["runs"][n]["timing"]["step_wall_seconds"]
                    e = m["accuracy_vs_fine"]["error_vs_fine"][n][c]
                    top = max(top, e)
                    a.plot([t], [e], st, label=n)
                a.set_xlabel("step loop, one thread (s)")
                a.set_title("%s: error vs the 0.05 um run" % c, fontsize=9)
                a.set_xlim(left=0); a.set_ylim(0, 1.15 * top)
            ax[0].legend(fontsize=6, loc="lower right")
            fig.tight_layout(); fig.savefig(os.path.join(out, "hybrid_cost_accuracy.png"), dpi=120)
        if "film_hybrid_unstructured_30um_fixed" in H:
            fig, ax = plt.subplots(1, 2, figsize=(11, 4))
            curves = [("film_extended_30um", H["film_extended_30um"], "k", 1.0),
                      ("film_hybrid_unstructured_30um_fixed", H["film_hybrid_unstructured_30um_fixed"], "c", 1.0)]
            if "accuracy_vs_fine" in m and "yardstick_30um" in m["accuracy_vs_fine"]:
                curves.append(("film_extended_30um at 0.05 um (yardstick)", fine30, "0.6", 0.8))
            for lab, h, col, lw in curves:
                for a, p in zip(ax, "EF"):
                    a.plot(h["time"] * 1e9, h[p + ".syy"] / 1e9, "-", color=col, lw=lw, label=lab)
            for a, p in zip(ax, "EF"):
                a.set_xlabel("t (ns)"); a.set_ylabel("sigma_yy at %s (GPa)" % p); a.legend(fontsize=7)
            fig.tight_layout(); fig.savefig(os.path.join(out, "hybrid_film_30um.png"), dpi=120)
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
    for key in ("benchmark", "benchmark_30um"):
        if key not in m:
            continue
        print("%s (step loops, one thread, CPU):" % key)
        for n, b in m[key]["cases"].items():
            print("  %-36s %6.3f s  x %.2f (min)  x %.2f (median)" % (
                n, b["step_cpu_seconds_min"], b["speedup_over_reference_min"],
                b["speedup_over_reference_median"]))
    if "accuracy_vs_fine" in m:
        print("error vs the 0.05 um extended run (E.syy F.syy E.J2 F.J2 E.sxx), equal accuracy:")
        for n, e in m["accuracy_vs_fine"]["error_vs_fine"].items():
            print("  %-36s %s  %s" % (n, " ".join("%.4f" % v for v in e.values()),
                                      m["accuracy_vs_fine"]["equal_accuracy"][n]))


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "out"))
