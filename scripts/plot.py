#!/usr/bin/python3
"""Plot history columns of one or more runs against time, one panel per column, one curve per
run (the look of the study figures: studies/common/style.py).

    scripts/plot.py RUN [RUN ...] -c COLUMN [-c COLUMN ...] [-o FILE.png] [--from T0] [--to T1]

RUN is an output folder (its history.csv is read) or a history.csv. A column is a name of
history.csv's header (`A.syy`, `energy.kinetic`) or a pattern with * (`A.*`, `*.vy`). Curves are
labelled with the folder name and, when the folder has summary.json, the run's title goes on the
figure. Without -o the figure is written to plot.png. Errors (a missing file, a column no run
has) are one line naming the file, and exit 1.
"""
import argparse
import fnmatch
import json
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "studies", "common"))
import style  # noqa: E402
from history import read_history  # noqa: E402


def fail(msg):
    print("plot.py: error: " + msg, file=sys.stderr)
    sys.exit(1)


def load(run):
    path = os.path.join(run, "history.csv") if os.path.isdir(run) else run
    if not os.path.isfile(path):
        fail(path + ": no such file (give an output folder or a history.csv)")
    try:
        cols = read_history(path)
    except (ValueError, StopIteration, OSError) as e:
        fail(path + ": not a history file (" + str(e) + ")")
    if "time" not in cols:
        fail(path + ": no time column (not a history file)")
    folder = os.path.dirname(os.path.abspath(path))
    title = ""
    summary = os.path.join(folder, "summary.json")
    if os.path.isfile(summary):
        try:
            with open(summary) as f:
                title = json.load(f).get("title", "")
        except (ValueError, OSError):
            pass
    return {"path": path, "label": os.path.basename(folder), "cols": cols, "title": title}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("runs", nargs="+", metavar="RUN")
    ap.add_argument("-c", "--column", action="append", required=True, help="column or pattern")
    ap.add_argument("-o", "--output", default="plot.png")
    ap.add_argument("--from", dest="t0", type=float, default=None)
    ap.add_argument("--to", dest="t1", type=float, default=None)
    a = ap.parse_args()

    runs = [load(r) for r in a.runs]
    columns = []
    for pat in a.column:
        found = [c for r in runs for c in r["cols"] if c != "time" and fnmatch.fnmatchcase(c, pat)]
        if not found:
            avail = sorted(c for c in runs[0]["cols"] if c != "time")
            fail(runs[0]["path"] + ": no column matches \"" + pat + "\"; columns: " + ", ".join(avail))
        for c in found:
            if c not in columns:
                columns.append(c)

    style.apply()
    import matplotlib.pyplot as plt
    t_end = max(r["cols"]["time"][-1] for r in runs)
    ts, tu = style.time_scale(t_end)
    fig, axes = plt.subplots(len(columns), 1, sharex=True, squeeze=False,
                             figsize=(6.4, 2.6 * len(columns) + 0.8))
    for ax, col in zip(axes[:, 0], columns):
        vs, vu = style.field_scale(col)
        for k, r in enumerate(runs):
            if col not in r["cols"]:
                continue
            t = r["cols"]["time"]
            keep = [i for i, x in enumerate(t) if (a.t0 is None or x >= a.t0) and (a.t1 is None or x <= a.t1)]
            ax.plot([t[i] * ts for i in keep], [r["cols"][col][i] * vs for i in keep],
                    label=r["label"], **style.line_style(k))
        ax.set_ylabel(col + (" (" + vu + ")" if vu else ""))
        if len(runs) > 1:
            ax.legend(loc="best")
    axes[-1, 0].set_xlabel("time (" + tu + ")")
    titles = sorted({r["title"] for r in runs if r["title"]})
    if len(titles) == 1:
        fig.suptitle(titles[0])
    try:
        fig.savefig(a.output)
    except OSError as e:
        fail(a.output + ": cannot write (" + str(e) + ")")
    print(a.output)


if __name__ == "__main__":
    main()
