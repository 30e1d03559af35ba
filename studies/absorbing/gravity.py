"""A column under gravity on each absorbing base, in MPM and in the FE far field, while a pulse
from the top is absorbed (docs/physics.md sections 9.1-9.3).

    /usr/bin/python3 studies/absorbing/gravity.py [OUTDIR]     (default studies/absorbing/out)

A steel column 4 cells wide and 200 cells high (h = 1 mm), rollers on its sides, its weight
switched on at t = 0 (g = 2000 m/s^2, so that the weight rho g L = 3.1 MPa is of the pulse's
size), and a sin^2 pressure pulse of the same amplitude on its top (16 cells FWHM). Its base is
one of: LK dashpots; Kelvin-Voigt springs standing for a column of the same length below it
(delta = L); a 20-cell mass-proportional damping band (r0 0.5) in front of LK; a 20-cell PML
(r0 1e-2, alpha 0) in front of LK. MPM under USL (the particle PML needs it), 1 ppc; FEM Q1.
Each base runs twice, with the pulse and without it.

The static state against its closed form, from the run without the pulse (the base's
displacement u_b, integrated from the base probe's velocity):
  * Kelvin-Voigt settles at u_b = -g L delta / c_d^2 (the weight on a spring rho c_d^2 / delta);
  * a dashpot carries no static load: the column sinks at the terminal velocity g L / c_d, with
    the band's damping in front at g L / (c_d (1 - ln r0)) (its force rho v alpha_0 L_d / 3 adds
    -ln r0 to the impedance), with the PML's at g L / (c_d (1 - ln(R0) / 2)) (its damping block
    m d; its memories vanish for a rigid motion).
The pulse: the difference of the two runs (the problem is linear) at a probe at mid-height,
after the incident pulse has passed: the largest reflected |sigma_yy| over the pulse's
amplitude.

Writes OUTDIR/gravity/metrics.json and OUTDIR/gravity/gravity_column.png and prints the table.
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

H = 1e-3             # cell (m)
W, L = 4 * H, 200 * H
E, NU, RHO = 200e9, 0.25, 7800.0
CD = np.sqrt(E * (1 - NU) / (RHO * (1 + NU) * (1 - 2 * NU)))
G = 2000.0           # m/s^2
SIGMA = RHO * G * L  # the weight per unit area, also the pulse's amplitude (Pa)
DUR = 2 * 16 * H / CD
BAND, R_BAND, R_PML = 20 * H, 0.5, 1e-2
T_END = 30 * L / CD  # 15 round trips
ALPHA = 2e4          # the frequency shift of the PML in front of Kelvin-Voigt (1/s)
BASES = ["lk", "kv", "damping", "pml", "pml_kv"]
NAMES = {"lk": "LK", "kv": "Kelvin–Voigt", "damping": "damping band + LK", "pml": "PML + LK",
         "pml_kv": "PML (α > 0) + Kelvin–Voigt"}


def closed_form(base):
    """('settle', u) or ('drift', v): the base's static displacement or its sinking speed; None
    where there is none (a PML: its stretched equations carry the layer's own weight in no
    physical way, and with alpha > 0 it is statically 1 + d / alpha times softer)."""
    if base == "kv":
        return "settle", -G * L * L / CD ** 2
    if base in ("lk", "damping"):
        z = {"lk": 1.0, "damping": 1 - np.log(R_BAND)}[base]
        return "drift", -G * L / (CD * z)
    return None


MATERIAL = {"steel": {"model": "elastic", "young": E, "poisson": NU, "density": RHO}}
PULSE = {"shape": "sin2", "start": 0, "duration": DUR, "ramp": DUR / 2}


def probes(base_y):
    return [{"name": "base", "at": [W / 2, base_y], "fields": ["vy", "syy"]},
            {"name": "mid", "at": [W / 2, L / 2 + H / 2], "fields": ["vy", "syy"]}]


def mpm_case(base, pulse):
    b = [{"type": "roller", "component": "x", "body": "col", "side": s} for s in ("left", "right")]
    if pulse:
        b.append({"type": "traction", "body": "col", "side": "top", "normal": -SIGMA, "time": PULSE})
    at = {"body": "col", "side": "bottom"}
    if base == "kv":
        b.append({"type": "kelvin_voigt", "delta": L, **at})
    elif base == "pml_kv":
        b.append({"type": "pml", "width": BAND, "r0": R_PML, "alpha": ALPHA, **at})
        b.append({"type": "kelvin_voigt", "delta": L, **at})
    else:
        if base == "damping":
            b.append({"type": "damping_layer", "width": BAND, "r0": R_BAND, **at})
        if base == "pml":
            b.append({"type": "pml", "width": BAND, "r0": R_PML, **at})
        b.append({"type": "silent", **at})
    return {"title": f"column under gravity, {base} base (MPM)", "time": {"end": T_END, "cfl": 0.5},
            "grid": {"origin": [-2 * H, -2 * H], "size": [W + 4 * H, L + 4 * H], "cell": H},
            "scheme": {"update": "USL", "threads": 1}, "gravity": [0, -G], "materials": MATERIAL,
            "bodies": [{"name": "col", "material": "steel", "box": [0, 0, W, L], "particles_per_cell": 1}],
            "boundaries": b, "probes": probes(H / 2),
            "output": {"snapshots": 0, "progress": False, "history_every": 1}}


GEO = """DefineConstant[ h = {%r, Name "Parameters/h"} ];
Point(1) = {0, 0, 0}; Point(2) = {%r, 0, 0}; Point(3) = {%r, %r, 0}; Point(4) = {0, %r, 0};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Transfinite Curve{1, 3} = Round(%r / h) + 1; Transfinite Curve{2, 4} = Round(%r / h) + 1;
Transfinite Surface{1}; Recombine Surface{1};
Physical Surface("body", 1) = {1};
Physical Curve("left", 11) = {4}; Physical Curve("right", 12) = {2};
Physical Curve("bottom", 13) = {1}; Physical Curve("top", 14) = {3};
""" % (H, W, W, L, L, W, L)


def fem_case(base, pulse, geo):
    b = [{"type": "roller", "component": "x", "curve": ["left", "right"]}]
    if pulse:
        b.append({"type": "traction", "curve": "top", "normal": -SIGMA, "time": PULSE})
    if base == "kv":
        b.append({"type": "kelvin_voigt", "curve": "bottom", "delta": L})
    elif base == "pml_kv":
        b.append({"type": "pml", "curve": "bottom", "width": BAND, "r0": R_PML, "alpha": ALPHA})
        b.append({"type": "kelvin_voigt", "curve": "bottom", "delta": L})
    else:
        if base == "damping":
            b.append({"type": "damping_layer", "curve": "bottom", "width": BAND, "r0": R_BAND})
        if base == "pml":
            b.append({"type": "pml", "curve": "bottom", "width": BAND, "r0": R_PML})
        b.append({"type": "dashpot", "curve": "bottom"})
    return {"title": f"column under gravity, {base} base (FEM)", "time": {"end": T_END, "cfl": 0.5},
            "scheme": {"threads": 1}, "gravity": [0, -G], "materials": MATERIAL,
            "fem": {"mesh": geo, "regions": {"body": "steel"}, "boundaries": b},
            "probes": probes(0.0), "output": {"snapshots": 0, "progress": False, "history_every": 1}}


def history(path):
    with open(path) as f:
        head = f.readline().strip().split(",")
    a = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    return {k: a[:, i] for i, k in enumerate(head)}


def run(case, out):
    path = out + ".json"
    with open(path, "w") as f:
        json.dump(case, f, indent=1)
    subprocess.run([BIN, "run", path, "--out", out, "--quiet"], check=True)
    return history(os.path.join(out, "history.csv"))


def base_displacement(h):
    t, v = h["time"], h["base.vy"]
    return t, np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * np.diff(t))])


def main(out):
    out = os.path.join(out, "gravity")
    os.makedirs(out, exist_ok=True)
    geo = os.path.join(out, "column.geo")
    with open(geo, "w") as f:
        f.write(GEO)
    metrics = {"column": {"cells": [4, 200], "cell_m": H, "c_d": CD, "g": G, "weight_pa": SIGMA,
                          "pulse_fwhm_cells": 16, "t_end_s": T_END}, "results": {}}
    curves = {}
    for method in ("mpm", "fem"):
        for base in BASES:
            hs = {}
            for pulse in (False, True):
                name = f"{method}_{base}_{'pulse' if pulse else 'static'}"
                case = mpm_case(base, pulse) if method == "mpm" else fem_case(base, pulse, geo)
                hs[pulse] = run(case, os.path.join(out, name))
            t, u = base_displacement(hs[False])
            late = t >= 0.5 * T_END  # the second half: settled, drifting steadily, or ringing
            slope = float(np.polyfit(t[late], u[late], 1)[0])
            mean = float(np.mean(u[late]))
            row = {"late_mean_displacement_m": mean, "late_drift_m_per_s": slope,
                   "late_range_m": [float(np.min(u[late])), float(np.max(u[late]))]}
            cf = closed_form(base)
            if cf:
                measured = mean if cf[0] == "settle" else slope
                row["closed_form"] = {cf[0]: cf[1], "measured": measured,
                                      "relative_error": abs(measured - cf[1]) / abs(cf[1])}
            # The pulse alone: the difference of the runs; reflected part at mid-height.
            d = hs[True]["mid.syy"] - np.interp(hs[True]["time"], hs[False]["time"], hs[False]["mid.syy"])
            tt = hs[True]["time"]
            win = (tt > 1.5 * L / CD - 0.5 * DUR) & (tt < 2.5 * L / CD - DUR)
            refl = float(np.max(np.abs(d[win])) / SIGMA)
            row["reflected_amplitude"] = refl
            metrics["results"][f"{method}_{base}"] = row
            curves[(method, base)] = (t, u)
            cmp = ""
            if cf:
                cmp = (f"closed form {cf[1]: .4e} ({100 * row['closed_form']['relative_error']:.2f} %)")
            print(f"{method:3s} {base:7s} late mean u {mean: .4e} m, drift {slope: .4e} m/s {cmp}; "
                  f"reflected pulse {refl:.4f}")
    with open(os.path.join(out, "metrics.json"), "w") as f:
        json.dump(metrics, f, indent=2)
    style.apply()
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.4))
    for ax, shown in zip(axes, (BASES, ("kv", "pml_kv"))):
        for k, base in enumerate(BASES):
            if base not in shown:
                continue
            c = style.COLOURS[k % len(style.COLOURS)]
            for method, ls in (("fem", "-"), ("mpm", ":")):
                t, u = curves[(method, base)]
                ax.plot(1e6 * t, 1e6 * u, ls=ls, color=c, label=f"{NAMES[base]} ({method.upper()})")
            cf = closed_form(base)
            if cf:  # a settled level, or a drift rate drawn through the FE run's last point
                t, u = curves[("fem", base)]
                y = np.full(2, cf[1]) if cf[0] == "settle" else u[-1] + cf[1] * (np.array([0.5, 1]) * t[-1] - t[-1])
                x = np.array([0, 1]) * t[-1] if cf[0] == "settle" else np.array([0.5, 1]) * t[-1]
                ax.plot(1e6 * x, 1e6 * y, color="k", lw=0.8, ls="--")
        ax.set_xlabel("time (µs)")
        ax.set_ylabel("base displacement (µm)")
    axes[0].set_title("All bases (dashed black: closed forms)")
    axes[1].set_title("The bases that carry the weight")
    axes[0].legend(loc="lower left", fontsize=7)
    fig.suptitle("Steel column under its weight with a pulse from the top: the base's displacement")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "gravity_column.png"))


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "out"))
