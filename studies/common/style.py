"""One look for every figure of the project (the study figures and scripts/plot.py): sizes,
fonts, a colour cycle that stays apart in grey print, SI units written out (µs, MPa), legends
placed where they cover least."""
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

# Colours that stay apart for colour-blind readers and in grey (Okabe-Ito), and line styles that
# tell curves apart where colours are not enough.
COLOURS = ["#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#000000", "#F0E442"]
LINESTYLES = ["-", "--", "-.", ":"]


def apply():
    plt.rcParams.update({
        "figure.figsize": (6.4, 4.2),
        "figure.dpi": 100,
        "savefig.dpi": 150,
        "savefig.bbox": "tight",
        "font.size": 10,
        "axes.titlesize": 11,
        "axes.labelsize": 10,
        "legend.fontsize": 9,
        "legend.frameon": False,
        "axes.grid": True,
        "grid.alpha": 0.3,
        "axes.prop_cycle": plt.cycler(color=COLOURS),
        "lines.linewidth": 1.4,
    })


def line_style(k):
    """Colour and dash of the k-th curve of a plot (k from 0)."""
    return {"color": COLOURS[k % len(COLOURS)],
            "linestyle": LINESTYLES[(k // len(COLOURS) + k) % len(LINESTYLES)]}


# Units of history.csv columns by field name (the part after the last dot), and the scale and
# label they are plotted with.
FIELD_UNITS = {
    "sxx": (1e-6, "MPa"), "syy": (1e-6, "MPa"), "szz": (1e-6, "MPa"), "sxy": (1e-6, "MPa"),
    "J2": (1e-12, "MPa²"), "vx": (1.0, "m/s"), "vy": (1.0, "m/s"), "px": (1.0, "kg/s"),
    "py": (1.0, "kg/s"), "mass": (1.0, "kg/m"), "fcx": (1.0, "N/m"), "fcy": (1.0, "N/m"),
    "div": (1.0, "1/s"), "curl": (1.0, "1/s"),
    "kinetic": (1.0, "J/m"), "elastic": (1.0, "J/m"), "dissipated": (1.0, "J/m"),
    "absorbed": (1.0, "J/m"), "external_work": (1.0, "J/m"), "imbalance": (1.0, "J/m"),
}


def field_scale(column):
    """(scale, unit) of a history column (e.g. "A.syy" -> (1e-6, "MPa")); (1, "") if unknown."""
    return FIELD_UNITS.get(column.rsplit(".", 1)[-1], (1.0, ""))


def time_scale(t_end):
    """(scale, unit) for a time axis ending at t_end seconds: ns, µs or ms."""
    if t_end < 1e-6:
        return 1e9, "ns"
    if t_end < 1e-3:
        return 1e6, "µs"
    if t_end < 1.0:
        return 1e3, "ms"
    return 1.0, "s"
