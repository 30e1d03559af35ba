"""Layer thickness and PML parameters against the reflection (studies/absorbing).

    /usr/bin/python3 studies/absorbing/scan.py [OUTDIR]    (default studies/absorbing/out)

Runs `build/oblique` (the plane-wave differencing of the angle study: 24-cell pulse, receiver
20.5 cells from the boundary) at 0, 45 and 75 degrees, P and SV, and records the largest
reflected amplitude of any type (same-type and converted) for:
  * thickness: the PML (r0 1e-2) and the damping band (r0 0.9) 2-15 cells, FEM Q1 and MPM (1 ppc;
    USL for the PML), LK dashpots behind each;
  * the PML's parameters at 10 cells, FEM: the profile power N (1-4), the design reflection r0
    (1e-1 to 1e-4) and the frequency shift alpha (0, 1e5, 1e6 1/s);
  * r0 for the MPM PML at 10 cells.
Thicker layers need the receiver further in: 10, 15 and 20 cells are run again with it
30.5 cells from the boundary (`oblique --receiver`). Writes OUTDIR/scan/scan.json and
OUTDIR/scan/scan.png and prints the tables. About 16 minutes on two cores.
"""
import json
import os
import subprocess
import sys

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(here, "..", "common"))
import style  # noqa: E402

import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.abspath(os.path.join(here, "..", ".."))
BIN = os.environ.get("OBLIQUE", os.path.join(ROOT, "build", "oblique"))
ANGLES = "0 45 75"
THICK = [2, 4, 6, 10, 15]
THICK_FAR = [10, 15, 20]  # with the receiver 30.5 cells in


def worst(out, method, boundary, **kw):
    """Largest reflected amplitude of any type over the angles and both waves."""
    d = os.path.join(out, "_".join([method, boundary] + [f"{k}{v}" for k, v in kw.items()]))
    args = [BIN, d, "--method", method, "--angles", ANGLES, "--boundary", boundary]
    for k, v in kw.items():
        args += [f"--{k}", str(v)]
    subprocess.run(args, check=True, stdout=subprocess.DEVNULL)
    j = json.load(open(os.path.join(d, "metrics.json" if method == "fem" else "metrics_mpm.json")))
    best, where = 0.0, ""
    for r in j["results"]:
        for k, v in r.items():
            if k.startswith("R_") and not k.endswith("exact") and v > best:
                best, where = v, f"{r['wave']} {r['angle_deg']:g} deg {k}"
    print(f"  {method} {boundary} {kw}: {best:.4f} ({where})", flush=True)
    return {"worst": best, "where": where}


def main(out):
    out = os.path.join(out, "scan")
    os.makedirs(out, exist_ok=True)
    res = {"angles_deg": [0, 45, 75], "thickness_cells": THICK, "thickness": {}, "pml_fem": {},
           "pml_mpm_r0": {}}
    print("thickness (largest reflected amplitude, any type):")
    for method in ("fem", "mpm"):
        for b, r0 in (("pml", 1e-2), ("damping", 0.9)):
            res["thickness"][f"{method}_{b}"] = [worst(out, method, b, band=n, r0=r0) for n in THICK]
    # The same at 10, 15 and 20 cells with the receiver 30.5 cells in: a 20-cell layer's cut
    # initial data would reach the incident pulse's tail at 20.5 (oblique.hpp, Setup::receiver).
    print("thickness, receiver 30.5 cells from the boundary:")
    res["thickness_receiver_30_5"] = {}
    for method in ("fem", "mpm"):
        for b, r0 in (("pml", 1e-2), ("damping", 0.9)):
            res["thickness_receiver_30_5"][f"{method}_{b}"] = [
                worst(out, method, b, band=n, r0=r0, receiver=30.5) for n in THICK_FAR]
    print("PML parameters, FEM, 10 cells:")
    res["pml_fem"]["power"] = {n: worst(out, "fem", "pml", band=10, r0=1e-2, power=n) for n in (1, 2, 3, 4)}
    res["pml_fem"]["r0"] = {r: worst(out, "fem", "pml", band=10, r0=r) for r in (1e-1, 1e-2, 1e-3, 1e-4)}
    res["pml_fem"]["alpha"] = {a: worst(out, "fem", "pml", band=10, r0=1e-2, alpha=a) for a in (0, 1e5, 1e6)}
    print("PML r0, MPM, 10 cells:")
    res["pml_mpm_r0"] = {r: worst(out, "mpm", "pml", band=10, r0=r) for r in (1e-1, 1e-2, 1e-3)}
    with open(os.path.join(out, "scan.json"), "w") as f:
        json.dump(res, f, indent=2)

    style.apply()
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    look = {"fem_pml": ("PML, FEM", "-", "o"), "mpm_pml": ("PML, MPM", ":", "s"),
            "fem_damping": ("damping band, FEM", "-", "o"), "mpm_damping": ("damping band, MPM", ":", "s")}
    for k, (key, (label, ls, mk)) in enumerate(look.items()):
        c = style.COLOURS[0 if "pml" in key else 2]
        axes[0].semilogy(THICK, [r["worst"] for r in res["thickness"][key]], ls=ls, marker=mk,
                         color=c, mfc="none" if "mpm" in key else c, label=label)
    axes[0].set_xlabel("layer thickness (cells)")
    axes[0].set_ylabel("largest reflected amplitude, 0/45/75°, P and SV")
    axes[0].set_title("Thickness (PML r0 1e-2, band r0 0.9; LK behind)")
    axes[0].legend(fontsize=8)
    for k, (name, xs) in enumerate((("power N", res["pml_fem"]["power"]),
                                    ("r0", res["pml_fem"]["r0"]))):
        keys = list(xs)
        axes[1].semilogy(range(len(keys)), [xs[x]["worst"] for x in keys], marker="o",
                         color=style.COLOURS[k + 3], label=f"{name}: " + ", ".join(f"{x:g}" for x in keys))
    axes[1].set_xticks(range(4))
    axes[1].set_xticklabels(["1st", "2nd", "3rd", "4th"])
    axes[1].set_xlabel("value (in the order of the legend)")
    axes[1].set_title("FE PML, 10 cells: profile power and r0")
    axes[1].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "scan.png"))


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "out"))
