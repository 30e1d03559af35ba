"""The PML half-space with its top face just past a grid line: the light nodes kept and extended
(scheme.light_nodes; docs/physics.md section 8.7).

    /usr/bin/python3 studies/absorbing/light_nodes.py [OUTDIR]   (default studies/absorbing/out)

examples/half-space-pml.json (MPM, 2 mm cells, 4 ppc, MUSL) with the grid moved down by
OFFSETS of a cell, so that its top particles lie (offset - 0.25) cells past a grid line; each
with `light_nodes` "keep" and "extend", without and with two terms of the mass correction. Against
its FE twin with 0.5 mm cells: relative L2 of the vertical velocity at the surface receivers 20
and 50 mm from the load over the 80 us, the late level (rms of the vertical velocity 20 mm out
over 40-80 us, after the surface wave) and the energy account (|imbalance| over the work).
At 0.1 and 0.2 no node is light: the two runs are the same.

Writes OUTDIR/light_nodes/metrics.json and OUTDIR/light_nodes/light_nodes.png (the receiver
20 mm out at the offset 0.3, and the misfit against the offset) and prints the table. About
40 s on 2 cores.
"""
import json
import os
import sys

import numpy as np

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(here, "..", "common"))
import style  # noqa: E402

import matplotlib.pyplot as plt  # noqa: E402

from half_space import FEM, MPM, T_END, relative_l2, run  # noqa: E402

CELL = 0.002
OFFSETS = [0.0, 0.1, 0.2, 0.3, 0.35, 0.4, 0.45, 0.5]
RECEIVERS = ["S20.vy", "S50.vy"]


def late_level(h):
    sel = (h["time"] >= 4e-5) & (h["time"] <= T_END * (1 + 1e-9))
    return float(np.sqrt(np.mean(h["S20.vy"][sel] ** 2)))


def account(h):
    return float(abs(h["energy.imbalance"][-1]) / h["energy.external_work"][-1])


def main(out):
    out = os.path.join(out, "light_nodes")
    os.makedirs(out, exist_ok=True)
    ref = run(FEM, ["fem.size=0.0005"], os.path.join(out, "fem_0.5mm"))
    metrics = {"reference": "FE Q1 with 0.5 mm cells", "receivers": RECEIVERS,
               "late_level": "rms of S20.vy over 40-80 us (m/s)",
               "account": "|energy.imbalance| / energy.external_work at the end", "runs": {}}
    runs = {}
    print(f"{'offset':>6s} {'terms':>5s} {'light nodes':>11s} " +
          " ".join(f"{r:>8s}" for r in RECEIVERS) + "    late    account")
    for offset in OFFSETS:
        grid = [f"grid.origin=[0,{-offset * CELL:.6g}]", "grid.size=[0.2,0.104]"]
        for terms in (0, 2):
            for mode in ("keep", "extend"):
                key = f"y{offset:g}_k{terms}_{mode}"
                o = grid + [f"scheme.light_nodes=\"{mode}\"", f"scheme.mass_correction={terms}"]
                h = run(MPM, o, os.path.join(out, key))
                runs[key] = h
                errs = [relative_l2(h, ref, c) for c in RECEIVERS]
                metrics["runs"][key] = {"offset": offset, "mass_correction": terms,
                                        "light_nodes": mode,
                                        "relative_l2": dict(zip(RECEIVERS, errs)),
                                        "late_level": late_level(h), "account": account(h)}
                print(f"{offset:6.2f} {terms:5d} {mode:>11s} " +
                      " ".join(f"{100 * e:7.1f}%" for e in errs) +
                      f"  {late_level(h):.4f}  {100 * account(h):6.2f}%")
    with open(os.path.join(out, "metrics.json"), "w") as f:
        json.dump(metrics, f, indent=1)

    style.apply()
    fig, (a0, a1) = plt.subplots(1, 2, figsize=(12.0, 4.2))
    a0.plot(ref["time"] * 1e6, ref["S20.vy"], color="black", lw=2.2, label="FE Q1, 0.5 mm")
    for i, (key, label) in enumerate([("y0.3_k0_keep", "MPM, light nodes kept"),
                                      ("y0.3_k0_extend", "MPM, light nodes extended"),
                                      ("y0_k0_keep", "MPM, body on the grid lines")]):
        h = runs[key]
        a0.plot(h["time"] * 1e6, h["S20.vy"], color=style.COLOURS[i],
                ls=style.LINESTYLES[i % len(style.LINESTYLES)], label=label)
    a0.set_xlabel("time (µs)")
    a0.set_ylabel("vertical velocity 20 mm along the surface (m/s)")
    a0.set_title("Top particles 0.05 cell past a grid line (2 mm cells)")
    a0.set_xlim(0, T_END * 1e6)
    a0.legend(loc="lower right")
    for i, (terms, mode) in enumerate([(0, "keep"), (0, "extend"), (2, "keep"), (2, "extend")]):
        y = [100 * metrics["runs"][f"y{o:g}_k{terms}_{mode}"]["relative_l2"]["S50.vy"]
             for o in OFFSETS]
        label = ("kept" if mode == "keep" else "extended") + \
            (", mass correction 2" if terms else "")
        a1.plot(OFFSETS, y, color=style.COLOURS[i], marker="o",
                ls=style.LINESTYLES[i % len(style.LINESTYLES)], label=label)
    a1.set_xlabel("grid offset below the body (cells)")
    a1.set_ylabel("S50 vy, relative L2 against FE (%)")
    a1.set_title("The surface receiver 50 mm out")
    a1.legend(loc="upper left")
    fig.savefig(os.path.join(out, "light_nodes.png"))


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "out"))
