"""The PML half-space across the methods: MPM's surface wave against FE's, with and without the
consistent-mass correction and the Gauss points (docs/physics.md section 1.1).

    /usr/bin/python3 studies/absorbing/half_space.py [OUTDIR]     (default studies/absorbing/out)

examples/half-space-pml.json (MPM, 2 mm cells, 4 ppc, MUSL, a 12 us sin^2 line load, 10-cell
PMLs with LK behind) and its FE twin examples/half-space-fem-pml.json (Q1, lumped mass). The
reference is the FE twin with 0.5 mm cells. Each run's receivers (the vertical velocity 20 and
50 mm from the load along the surface, and 50 mm deep) against the reference, relative L2 over
the 80 us of the run:
  * FE, 2 mm and 1 mm;
  * MPM with the particles at the sub-cells' centres (the default), with one and two terms of
    scheme.mass_correction, and at the cells' Gauss points ("seeding": "gauss") with two terms;
    two terms in the symmetric form (scheme.mass_correction_form), at the centres and the Gauss
    points;
    each with 2 mm and 1 mm cells;
  * the hybrid examples/half-space-hybrid.json (particles in a 60 x 30 mm window under the load,
    the FE twin's elements around it), 2 mm cells: the default window, two terms of the
    correction, and the Gauss points with two terms (docs/physics.md section 7).

Writes OUTDIR/half_space/metrics.json, OUTDIR/half_space/half_space_methods.png and
OUTDIR/half_space/half_space_hybrid.png (the receiver 50 mm along the surface) and prints the
table. About 30 s on 2 cores.
"""
import json
import os
import subprocess
import sys

import numpy as np

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(here, "..", "common"))
import style  # noqa: E402

import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.abspath(os.path.join(here, "..", ".."))
BIN = os.environ.get("SILENTMPM", os.path.join(ROOT, "build", "silentmpm"))
MPM = os.path.join(ROOT, "examples", "half-space-pml.json")
FEM = os.path.join(ROOT, "examples", "half-space-fem-pml.json")
HYBRID = os.path.join(ROOT, "examples", "half-space-hybrid.json")
RECEIVERS = ["S20.vy", "S50.vy", "D50.vy"]
T_END = 8e-5

# name: (case, overrides, label)
MPM_RUNS = {
    "uniform": ([], "MPM, sub-cell centres"),
    "corrected_1": (["scheme.mass_correction=1"], "MPM, mass correction 1"),
    "corrected_2": (["scheme.mass_correction=2"], "MPM, mass correction 2"),
    "gauss_2": (["bodies.0.seeding=gauss", "scheme.mass_correction=2"],
                "MPM, Gauss points, mass correction 2"),
    "symmetric_2": (["scheme.mass_correction=2", "scheme.mass_correction_form=symmetric"],
                    "MPM, mass correction 2, symmetric form"),
    "gauss_symmetric_2": (["bodies.0.seeding=gauss", "scheme.mass_correction=2",
                           "scheme.mass_correction_form=symmetric"],
                          "MPM, Gauss points, mass correction 2, symmetric form"),
}

HYBRID_RUNS = {
    "hybrid": ([], "hybrid window, sub-cell centres"),
    "hybrid_corrected_2": (["scheme.mass_correction=2"], "hybrid window, mass correction 2"),
    "hybrid_gauss_2": (["bodies.0.seeding=gauss", "scheme.mass_correction=2"],
                       "hybrid window, Gauss points, mass correction 2"),
}


def history(path):
    with open(os.path.join(path, "history.csv")) as f:
        head = f.readline().strip().split(",")
        data = np.loadtxt(f, delimiter=",")
    return {k: data[:, i] for i, k in enumerate(head)}


def run(case, overrides, out):
    cmd = [BIN, "run", case, "--out", out, "--quiet", "--set", "output.snapshots=0"]
    for o in overrides:
        cmd += ["--set", o]
    subprocess.run(cmd, check=True)
    return history(out)


def relative_l2(a, ref, col):
    t = a["time"]
    keep = t <= T_END * (1 + 1e-9)
    b = np.interp(t[keep], ref["time"], ref[col])
    return float(np.sqrt(np.sum((a[col][keep] - b) ** 2) / np.sum(b ** 2)))


def main(out):
    out = os.path.join(out, "half_space")
    os.makedirs(out, exist_ok=True)
    ref = run(FEM, ["fem.size=0.0005"], os.path.join(out, "fem_0.5mm"))
    runs = {}
    for cell in ("2mm", "1mm"):
        fine = cell == "1mm"
        runs[f"fem_{cell}"] = (run(FEM, ["fem.size=0.001"] if fine else [],
                                   os.path.join(out, f"fem_{cell}")), f"FE Q1, {cell[:-2]} mm")
        for name, (o, label) in MPM_RUNS.items():
            extra = ["grid.cell=0.001", "grid.size=[0.2,0.101]"] if fine else []
            runs[f"{name}_{cell}"] = (run(MPM, o + extra, os.path.join(out, f"{name}_{cell}")),
                                      f"{label}, {cell[:-2]} mm")
    for name, (o, label) in HYBRID_RUNS.items():
        runs[f"{name}_2mm"] = (run(HYBRID, o, os.path.join(out, f"{name}_2mm")),
                               f"{label}, 2 mm")
    metrics = {"reference": "FE Q1 with 0.5 mm cells", "receivers": RECEIVERS, "runs": {},
               "against_fe_same_cells": "relative_l2_fe_2mm: against FE Q1 with 2 mm cells"}
    print(f"{'run':50s} " + " ".join(f"{r:>8s}" for r in RECEIVERS) + "   against FE, 2 mm")
    fe2 = runs["fem_2mm"][0]
    for key, (h, label) in runs.items():
        errs = [relative_l2(h, ref, c) for c in RECEIVERS]
        same = [relative_l2(h, fe2, c) for c in RECEIVERS]
        metrics["runs"][key] = {"label": label, "relative_l2": dict(zip(RECEIVERS, errs))}
        if key.endswith("_2mm") and key != "fem_2mm":
            metrics["runs"][key]["relative_l2_fe_2mm"] = dict(zip(RECEIVERS, same))
        print(f"{label:50s} " + " ".join(f"{100 * e:7.2f}%" for e in errs) +
              ("   " + " ".join(f"{100 * e:6.2f}%" for e in same) if key.endswith("_2mm") else ""))
    with open(os.path.join(out, "metrics.json"), "w") as f:
        json.dump(metrics, f, indent=1)

    style.apply()
    s50_figure(ref, runs, ["fem_2mm", "uniform_2mm", "corrected_1_2mm", "gauss_2_2mm"],
               "The surface wave in MPM and FE (2 mm cells)",
               os.path.join(out, "half_space_methods.png"))
    # The hybrid: the surface wave made in the particles, read 20 mm beyond the interface.
    s50_figure(ref, runs, ["fem_2mm", "hybrid_2mm", "hybrid_gauss_2_2mm"],
               "A particle window in the FE half-space (2 mm cells)",
               os.path.join(out, "half_space_hybrid.png"))


def s50_figure(ref, runs, keys, title, path):
    """The receiver 50 mm along the surface: the reference and the runs of `keys`."""
    fig, ax = plt.subplots(figsize=(7.0, 4.2))
    ax.plot(ref["time"] * 1e6, ref["S50.vy"], color="black", lw=2.2, label="FE Q1, 0.5 mm")
    for i, key in enumerate(keys):
        h, label = runs[key]
        ax.plot(h["time"] * 1e6, h["S50.vy"], color=style.COLOURS[i],
                ls=style.LINESTYLES[i % len(style.LINESTYLES)], label=label)
    ax.set_xlabel("time (µs)")
    ax.set_ylabel("vertical velocity 50 mm along the surface (m/s)")
    ax.set_title(title)
    ax.set_xlim(0, T_END * 1e6)
    ax.legend(loc="lower right")
    fig.savefig(path)

if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "out"))
