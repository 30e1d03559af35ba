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



# Readable names of the runs in the figures (the run names are those of studies/hybrid/run).
LABEL = {
    "film_extended": "all-MPM, extended substrate 15 µm (reference)",
    "film_silent": "all-MPM, silent bottom, substrate 5 µm",
    "film_hybrid_fixed": "hybrid, uniform Q1 far field, fixed bottom",
    "film_hybrid_dashpot": "hybrid, uniform Q1 far field, LK dashpot bottom",
    "film_hybrid_coarse_fixed": "hybrid, graded coarse Q1 far field, fixed bottom",
    "film_hybrid_unstructured_fixed": "hybrid, unstructured Q1 far field, fixed bottom",
    "film_hybrid_unstructured_1um_fixed": "hybrid, unstructured Q1 far field, fixed bottom, 1 µm of particles",
    "film_extended_30um": "all-MPM, extended substrate 30 µm (reference)",
    "film_hybrid_unstructured_30um_fixed": "hybrid, unstructured Q1 far field to 30 µm, fixed bottom",
    "pulse_extended": "all-MPM, extended plate (reference)",
    "pulse_silent": "all-MPM, silent right side",
    "pulse_hybrid_extended": "hybrid, Q1 far field to the extended plate's free end",
    "pulse_hybrid_dashpot": "hybrid, Q1 far field with LK dashpots",
}


def looks(style):
    """Line look of each run: the all-MPM extended reference a wide light-grey band under the
    others (as in the pulse study's Figs. 5-7), the others colours of style.COLOURS with their own
    dashes (apart in grey print), one run the same look in every figure."""
    c = style.COLOURS
    ref = dict(color="0.72", ls="-", lw=3.6, zorder=1)
    return {
        "film_extended": ref, "film_extended_30um": ref, "pulse_extended": ref,
        "film_silent": dict(color=c[1], ls="--"), "pulse_silent": dict(color=c[1], ls="--"),
        "film_hybrid_unstructured_fixed": dict(color=c[0], ls="-"),
        "film_hybrid_unstructured_30um_fixed": dict(color=c[0], ls="-"),
        "film_hybrid_fixed": dict(color=c[2], ls="-."),
        "pulse_hybrid_extended": dict(color=c[2], ls="-."),
        "film_hybrid_dashpot": dict(color=c[6], ls=":"),
        "pulse_hybrid_dashpot": dict(color=c[6], ls=":"),
        "film_hybrid_coarse_fixed": dict(color=c[3], ls=(0, (5, 1.5, 1, 1.5, 1, 1.5))),
    }


YARDSTICK = dict(color="0.35", ls="-", lw=0.7)  # the 0.05 µm all-MPM run: thin dark grey


def figures(out, m, H, fine, fine30):
    """hybrid_film.png, hybrid_cost_accuracy.png, hybrid_film_30um.png, hybrid_pulse.png in OUTDIR
    (fine, fine30: the 0.05 µm yardstick histories, or None)."""
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
    import style
    import matplotlib.pyplot as plt
    style.apply()
    look = looks(style)

    def panels(runs, yard, yard_label, cols, ylabels, t_end, title, path, window=None):
        """One panel per column, one curve per run, the legend under the panels (off the data)."""
        ts, tu = style.time_scale(t_end)
        fig, ax = plt.subplots(1, len(cols), figsize=(11, 4.2))
        for a, (c, scale, ptitle), ylabel in zip(ax, cols, ylabels):
            for n in runs:
                a.plot(H[n]["time"] * ts, H[n][c] * scale, label=LABEL[n], **look[n])
            if yard is not None:
                a.plot(yard["time"] * ts, yard[c] * scale, label=yard_label, **YARDSTICK)
            if window is not None:
                a.axvline(window[0] * ts, color="0.3", lw=0.9, ls=(0, (6, 2, 1, 2)), zorder=0,
                          label=window[1] % (window[0] * ts, tu))
            a.set_xlabel("time (%s)" % tu)
            a.set_ylabel(ylabel)
            a.set_title(ptitle)
        handles, labels = ax[0].get_legend_handles_labels()
        fig.legend(handles, labels, loc="upper center", bbox_to_anchor=(0.5, 0.0), ncol=2)
        fig.suptitle(title)
        fig.tight_layout()
        fig.savefig(os.path.join(out, path))
        plt.close(fig)

    below = "0.05 µm below the W–Si interface"
    film_cols = [("E.syy", 1e-9, "probe E, x = 4.95 µm, " + below),
                 ("F.syy", 1e-9, "probe F, x = 0.95 µm, " + below)]
    panels(["film_extended", "film_silent", "film_hybrid_fixed", "film_hybrid_dashpot",
            "film_hybrid_coarse_fixed", "film_hybrid_unstructured_fixed"],
           fine, "all-MPM, extended substrate 15 µm, 0.05 µm cells (accuracy yardstick)",
           film_cols, [r"$\sigma_{yy}$ at E (GPa)", r"$\sigma_{yy}$ at F (GPa)"], m["window"]["film"][1],
           "Tungsten film on silicon, 1.3 GPa step: all-MPM and hybrid runs (0.1 µm cells)",
           "hybrid_film.png")
    # Cost against accuracy: step-loop CPU time (build/bench_hybrid where it ran, else the
    # timing runs' step wall time) and the error against the 0.05 um run.
    if "accuracy_vs_fine" in m:
        bc = m.get("benchmark", {}).get("cases", {})
        c = style.COLOURS
        show = [("film_extended", "extended", dict(marker="s", color="0.45")),
                ("film_silent", "film_silent", dict(marker="v", color=c[1])),
                ("film_hybrid_coarse_fixed", "film_hybrid_coarse_fixed", dict(marker="^", color=c[3])),
                ("film_hybrid_unstructured_fixed", "film_hybrid_unstructured_fixed",
                 dict(marker="o", color=c[0])),
                ("film_hybrid_unstructured_1um_fixed", "film_hybrid_unstructured_1um_fixed",
                 dict(marker="D", color=c[4]))]
        fig, ax = plt.subplots(1, 4, figsize=(14, 3.6), sharex=True)
        for a, (col, what) in zip(ax, [("E.syy", r"$\sigma_{yy}$ at E"), ("F.syy", r"$\sigma_{yy}$ at F"),
                                       ("E.J2", r"$J_2$ at E"), ("F.J2", r"$J_2$ at F")]):
            top = 0
            for n, bn, st in show:
                if not m["runs"][n]["timing"]:
                    continue
                t = bc[bn]["step_cpu_seconds_min"] if bn in bc else m["runs"][n]["timing"]["step_wall_seconds"]
                e = m["accuracy_vs_fine"]["error_vs_fine"][n][col]
                top = max(top, e)
                a.plot([t], [e], ls="none", ms=7, label=LABEL[n], **st)
            a.set_xlabel("step loop, one thread (s)")
            a.set_title(what)
            a.set_xlim(left=0); a.set_ylim(0, 1.15 * top)
        ax[0].set_ylabel("relative L2 error against\nthe 0.05 µm run, 0–3.2 ns")
        handles, labels = ax[0].get_legend_handles_labels()
        fig.legend(handles, labels, loc="upper center", bbox_to_anchor=(0.5, 0.0), ncol=3)
        fig.suptitle("Film: cost (step-loop CPU time) against accuracy (error against the all-MPM "
                     "run at 0.05 µm cells)")
        fig.tight_layout()
        fig.savefig(os.path.join(out, "hybrid_cost_accuracy.png"))
        plt.close(fig)
    if "film_hybrid_unstructured_30um_fixed" in H:
        panels(["film_extended_30um", "film_hybrid_unstructured_30um_fixed"],
               fine30, "all-MPM, extended substrate 30 µm, 0.05 µm cells (accuracy yardstick)",
               film_cols, [r"$\sigma_{yy}$ at E (GPa)", r"$\sigma_{yy}$ at F (GPa)"], m["window"]["film_30um"][1],
               "Tungsten film on a 30 µm silicon substrate, to 6.4 ns: all-MPM and hybrid",
               "hybrid_film_30um.png")
    panels(["pulse_extended", "pulse_silent", "pulse_hybrid_extended", "pulse_hybrid_dashpot"],
           None, None, [("A.sxx", 1e-6, "longitudinal stress at A"),
                        ("A.syy", 1e-6, "lateral stress at A")],
           [r"$\sigma_{xx}$ at A (MPa)", r"$\sigma_{yy}$ at A (MPa)"], H["pulse_extended"]["time"][-1],
           "Plate under a compressive pulse: all-MPM and hybrid runs", "hybrid_pulse.png",
           window=(m["window"]["pulse"][1], "end of the comparison window (%.0f %s)"))


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
        figures(out, m, H, fine if "accuracy_vs_fine" in m else None,
                fine30 if "yardstick_30um" in m.get("accuracy_vs_fine", {}) else None)
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
