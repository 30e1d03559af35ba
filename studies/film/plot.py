#!/usr/bin/python3
"""Figures 16-25 and metrics.json of the film study (studies/film/README.md).

    /usr/bin/python3 studies/film/plot.py OUTDIR

Reads OUTDIR/<run>/history.csv, summary.json, probes.csv and particles.h5 as written by
studies/film/run.
"""
import json
import os
import sys

import h5py
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
import style  # noqa: E402

import matplotlib.pyplot as plt  # noqa: E402

T_FIG = 2.88e-9      # time of the deformed configurations (paper Figs. 16-18)
T_CMP = 3.2e-9       # comparison window end (extended bottom reflection returns at 3.25 ns)
MAGNIFY = 10.0
STATE_NAMES = ["elastic", "plastic", "decohesion", "separated"]
# Elastic particles a neutral light grey (the bulk), the others colours of style.COLOURS.
STATE_COLOURS = ["#c8c8c8", style.COLOURS[0], style.COLOURS[4], style.COLOURS[1]]


def history(path):
    with open(path) as f:
        head = f.readline().strip().split(",")
    a = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    return {k: a[:, i] for i, k in enumerate(head)}


def rel_l2(a, b, col, t1):
    t = b["time"]
    m = t <= t1 + 1e-15
    x = np.interp(t[m], a["time"], a[col])
    y = b[col][m]
    return float(np.linalg.norm(x - y) / np.linalg.norm(y))


def snapshot_at(h5path, t):
    with h5py.File(h5path, "r") as f:
        # The snapshot groups (step_<n>, each with its time); other entries (the XDMF
        # topology's vertices_<n>) are not snapshots.
        names = sorted(n for n in f.keys()
                       if isinstance(f[n], h5py.Group) and "time" in f[n].attrs)
        times = np.array([f[n].attrs["time"] for n in names])
        k = int(np.argmin(np.abs(times - t)))
        g0, g = f[names[0]], f[names[k]]
        order0 = np.argsort(g0["id"][:])
        order = np.argsort(g["id"][:])
        d = {
            "time": float(times[k]),
            "x0": g0["xyz"][:][order0, :2],
            "x": g["xyz"][:][order, :2],
            "state": g["state"][:][order],
            "eps_p": g["eps_p"][:][order],
            "body": g["body"][:][order],
            "nx": g["normal"][:][order, 0],
            "ny": g["normal"][:][order, 1],
        }
    return d


def counts(snap):
    film = snap["body"] == 0
    st = snap["state"][film]
    return {name: int(np.sum(st == i)) for i, name in enumerate(STATE_NAMES)}


def figure_deformed(snap, title, path, cell):
    x0, x = snap["x0"], snap["x"]
    xm = x0 + MAGNIFY * (x - x0)
    state = snap["state"].copy()
    # Non-film materials have no state machine: show their yielded points as plastic.
    other = snap["body"] != 0
    state[other & (snap["eps_p"] > 0)] = 1
    keep = x0[:, 1] >= -1e-12  # the film and the upper 5 um of the substrate
    fig, ax = plt.subplots(figsize=(7.5, 6.2))
    # Marker side about one particle spacing: the axes span ~11 um over ~6.6 in (475 pt).
    size = (0.85 * cell * 1e6 * 475.0 / 11.0) ** 2
    for i, name in enumerate(STATE_NAMES):
        m = keep & (state == i)
        if np.any(m):
            ax.scatter(xm[m, 0] * 1e6, xm[m, 1] * 1e6, s=size, c=STATE_COLOURS[i], marker="s",
                       linewidths=0, label=f"{name} ({int(np.sum(m & (snap['body'] == 0)))} in film)")
    # Critical-plane traces of the decohesion / separated particles.
    m = keep & (snap["state"] >= 2)
    if np.any(m):
        tx, ty = -snap["ny"][m], snap["nx"][m]
        h = 0.45 * cell * 1e6
        X, Y = xm[m, 0] * 1e6, xm[m, 1] * 1e6
        ax.plot(np.vstack([X - h * tx, X + h * tx]), np.vstack([Y - h * ty, Y + h * ty]),
                color="k", lw=0.35, alpha=0.6)
    ax.set_aspect("equal")
    ax.grid(False)
    ax.set_xlabel(f"x (µm), displacement ×{MAGNIFY:.0f}")
    ax.set_ylabel(f"y (µm), displacement ×{MAGNIFY:.0f}")
    ax.set_title(f"{title}\nt = {snap['time'] * 1e9:.2f} ns, displacements magnified {MAGNIFY:.0f}×")
    # The legend under the axes: inside it would hide particles.
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.1), markerscale=3, ncol=4,
              handletextpad=0.3, columnspacing=1.2)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def figure_lines(runs, col, ylabel, title, path, scale):
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    ts, tu = style.time_scale(T_CMP)
    for k, (label, h) in enumerate(runs):
        m = h["time"] <= T_CMP + 1e-15
        ax.plot(h["time"][m] * ts, h[col][m] * scale, label=label, **style.line_style(k))
    # The silicon round trip, explained in the legend (no text over the curves).
    ax.axvline(1.08e-9 * ts, color="0.5", lw=0.9, ls=(0, (6, 2, 1, 2)), zorder=0,
               label=f"Si round trip through 5 µm ({1.08e-9 * ts:.2f} {tu})")
    ax.set_xlabel(f"time ({tu})")
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    fig.tight_layout()
    # The legend outside on the right (as in the pulse study's figures), added after the layout
    # so that the axes keep their size: it covers no curve; the tight bounding box takes it in.
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0)
    fig.savefig(path)
    plt.close(fig)


def interface_columns(h, field):
    """Columns I_00.<field>, I_01.<field>, ... of the probe along the interface, in order."""
    return sorted(k for k in h if k.startswith("I_") and k.endswith("." + field))


def interface_positions(out, name):
    """x (m) of the interface probe points, from OUTDIR/<run>/probes.csv."""
    xs = {}
    with open(os.path.join(out, name, "probes.csv")) as f:
        f.readline()
        for line in f:
            n, x, y, along, s = line.strip().split(",")
            if along == "I":
                xs[n] = float(x)
    return xs


def interface_rel_l2(a, b, field, t1):
    """Relative L2 over the interface points and 0 <= t <= t1 (space-time field)."""
    num = den = 0.0
    for col in interface_columns(b, field):
        t = b["time"]
        m = t <= t1 + 1e-15
        x = np.interp(t[m], a["time"], a[col])
        num += float(np.sum((x - b[col][m]) ** 2))
        den += float(np.sum(b[col][m] ** 2))
    return float(np.sqrt(num / den))


def figure_interface(out, H, path):
    """sigma_yy along the W-Si interface (probe along the gmsh curve "interface") at three times."""
    xs = interface_positions(out, "silent")
    cols = interface_columns(H["silent"], "syy")
    x = np.array([xs[c.split(".")[0]] for c in cols]) * 1e6
    times = (1.0e-9, 2.0e-9, T_FIG)
    fig, axes = plt.subplots(1, len(times), figsize=(12, 3.8), sharey=True)
    for ax, t in zip(axes, times):
        for j, (label, name) in enumerate([("fixed 5 µm", "fixed"), ("extended 15 µm", "extended"),
                                           ("silent 5 µm", "silent")]):
            h = H[name]
            k = int(np.argmin(np.abs(h["time"] - t)))
            ax.plot(x, [h[c][k] * 1e-9 for c in cols], marker="o", ms=3, lw=1.2, label=label,
                    **style.line_style(j))
        ax.set_title(f"t = {t * 1e9:.2f} ns")
        ax.set_xlabel("x along the interface (µm)")
    axes[0].set_ylabel(r"$\sigma_{yy}$ at the interface, substrate side (GPa)")
    axes[0].legend(loc="best")
    fig.suptitle(r"$\sigma_{yy}$ along the W–Si interface (21 points of a probe along the gmsh curve "
                 "\"interface\")")
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "out")
    style.apply()
    H = {}
    for name in ["fixed", "extended", "silent", "cell_0.05", "cell_0.167", "ppc_4", "ppc_9",
                 "extended_usl", "silent_usl", "pml"]:
        p = os.path.join(out, name, "history.csv")
        if os.path.exists(p):
            H[name] = history(p)
    metrics = {"comparison_window_s": [0.0, T_CMP], "relative_l2_syy": {}, "particles": {}}
    for P in ["E", "F"]:
        col = f"{P}.syy"
        metrics["relative_l2_syy"][P] = {
            "silent_vs_extended": rel_l2(H["silent"], H["extended"], col, T_CMP),
            "fixed_vs_extended": rel_l2(H["fixed"], H["extended"], col, T_CMP),
        }
    # Absorbing layers under USL: the silent bottom alone and with a 1 um PML, against the
    # extended substrate under the same scheme (sigma_yy and J2 at E and F, sigma_yy and
    # sigma_xy along the interface).
    if all(n in H for n in ("extended_usl", "silent_usl", "pml")):
        ref = H["extended_usl"]
        layers = {}
        for n in ("silent_usl", "pml"):
            row = {f"{P}.{f}": rel_l2(H[n], ref, f"{P}.{f}", T_CMP)
                   for P in ("E", "F") for f in ("syy", "J2")}
            if interface_columns(H[n], "syy"):
                for f in ("syy", "sxy"):
                    row[f"interface.{f}"] = interface_rel_l2(H[n], ref, f, T_CMP)
            layers[n + "_vs_extended_usl"] = row
        layers["extended_usl_vs_extended"] = {
            f"{P}.syy": rel_l2(ref, H["extended"], f"{P}.syy", T_CMP) for P in ("E", "F")}
        metrics["layers_usl"] = layers
    # The whole interface (21 points of the probe along the gmsh curve "interface").
    if interface_columns(H["silent"], "syy"):
        metrics["interface_relative_l2"] = {
            f: {"silent_vs_extended": interface_rel_l2(H["silent"], H["extended"], f, T_CMP),
                "fixed_vs_extended": interface_rel_l2(H["fixed"], H["extended"], f, T_CMP)}
            for f in ("syy", "sxy")}
        metrics["interface_relative_l2"]["points"] = len(interface_columns(H["silent"], "syy"))
        figure_interface(out, H, os.path.join(out, "figure25.png"))
    titles = {
        "fixed": ("figure16.png", "Fixed bottom, substrate 5 µm"),
        "extended": ("figure17.png", "Fixed bottom, substrate 15 µm (extended; upper 5 µm shown)"),
        "silent": ("figure18.png", "Silent bottom, substrate 5 µm"),
    }
    for name, (fig, title) in titles.items():
        snap = snapshot_at(os.path.join(out, name, "particles.h5"), T_FIG)
        figure_deformed(snap, title, os.path.join(out, fig), 1e-7)
        end = snapshot_at(os.path.join(out, name, "particles.h5"), 1.0)
        metrics["particles"][name] = {"at_2.88ns": counts(snap), "at_3.2ns": counts(end)}
    # sigma_yy at E and F for the three substrates.
    three = [("fixed 5 µm", H["fixed"]), ("extended 15 µm", H["extended"]),
             ("silent 5 µm", H["silent"])]
    figure_lines(three, "E.syy", r"$\sigma_{yy}$ at E (GPa)",
                 r"$\sigma_{yy}$ at E (x = 4.95 µm, 0.05 µm below the interface)",
                 os.path.join(out, "figure19.png"), 1e-9)
    figure_lines(three, "F.syy", r"$\sigma_{yy}$ at F (GPa)",
                 r"$\sigma_{yy}$ at F (x = 0.95 µm, 0.05 µm below the interface)",
                 os.path.join(out, "figure20.png"), 1e-9)
    # J2 convergence: cell size and particles per cell (silent bottom).
    cells = [(lab, H[k]) for lab, k in [("0.05 µm", "cell_0.05"), ("0.1 µm", "silent"),
                                         ("0.167 µm", "cell_0.167")] if k in H]
    ppcs = [(lab, H[k]) for lab, k in [("1 ppc", "silent"), ("4 ppc", "ppc_4"),
                                        ("9 ppc", "ppc_9")] if k in H]
    for fig, runs, P, what in [("figure21.png", cells, "E", "cell size"),
                               ("figure22.png", cells, "F", "cell size"),
                               ("figure23.png", ppcs, "E", "particles per cell"),
                               ("figure24.png", ppcs, "F", "particles per cell")]:
        figure_lines(runs, f"{P}.J2", f"$J_2$ at {P} (GPa²)", f"$J_2$ at {P}, silent bottom: {what}",
                     os.path.join(out, fig), 1e-18)
    # Convergence numbers: relative L2 of J2 against the finest / densest run.
    conv = {}
    for P in ["E", "F"]:
        col = f"{P}.J2"
        if "cell_0.05" in H:
            conv[f"{P}.J2_cell_0.1_vs_0.05"] = rel_l2(H["silent"], H["cell_0.05"], col, T_CMP)
            if "cell_0.167" in H:
                conv[f"{P}.J2_cell_0.167_vs_0.05"] = rel_l2(H["cell_0.167"], H["cell_0.05"], col, T_CMP)
        if "ppc_9" in H:
            conv[f"{P}.J2_ppc_1_vs_9"] = rel_l2(H["silent"], H["ppc_9"], col, T_CMP)
            if "ppc_4" in H:
                conv[f"{P}.J2_ppc_4_vs_9"] = rel_l2(H["ppc_4"], H["ppc_9"], col, T_CMP)
    metrics["convergence_relative_l2"] = conv
    # Wall time: one thread, no snapshots, best of three.
    wall = {}
    for c in ["fixed", "silent"]:
        ts = []
        for k in (1, 2, 3):
            p = os.path.join(out, f"time_{c}_{k}", "summary.json")
            if os.path.exists(p):
                s = json.load(open(p))
                ts.append((s["wall_seconds"], s["step_seconds"], s["particles"], s["steps"]))
        if ts:
            best = min(ts)
            wall[c] = {"wall_seconds": best[0], "step_seconds": best[1], "particles": best[2],
                       "steps": best[3], "runs": len(ts)}
    if "fixed" in wall and "silent" in wall:
        wall["silent_over_fixed_step_time"] = wall["silent"]["step_seconds"] / wall["fixed"]["step_seconds"]
    metrics["timing_one_thread"] = wall
    energy = {}
    for name in ["fixed", "extended", "silent"]:
        s = json.load(open(os.path.join(out, name, "summary.json")))
        energy[name] = s["energy"]
    metrics["energy"] = energy
    with open(os.path.join(out, "metrics.json"), "w") as f:
        json.dump(metrics, f, indent=2)
    print(json.dumps(metrics, indent=2))


if __name__ == "__main__":
    main()
