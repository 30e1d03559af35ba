"""Helpers shared by the study scripts: read a history.csv, and compare two runs' columns with
`silentmpm compare` (relative L2 of A against B over a time window)."""
import csv
import subprocess


def read_history(path):
    """history.csv as {column name: list of floats}."""
    with open(path) as f:
        r = csv.reader(f)
        head = next(r)
        cols = {h: [] for h in head}
        for row in r:
            for h, v in zip(head, row):
                cols[h].append(float(v))
    return cols


def compare(binary, a, b, col, t0=None, t1=None):
    """Relative L2 difference of column `col` of history a against b (optionally over [t0, t1])."""
    cmd = [binary, "compare", a, b, "--column", col]
    if t0 is not None:
        cmd += ["--from", str(t0)]
    if t1 is not None:
        cmd += ["--to", str(t1)]
    res = subprocess.run(cmd, capture_output=True, text=True, check=True)
    return float(res.stdout.strip())
