"""Shared look of every figure: colours by role, display units, "no data" panels, saving.

Colours mean the same thing in every figure: grey for training runs (the design), blue for the
posterior (samples and posterior predictions), red for the measurement, orange for the emulator
or toy model, green for reference values (the config's `study.reference_sets`); purple and orange
for the early and late mixture components of the feature extractor.

Display units (what a shock physicist reads): A and B in MPa, shear moduli in GPa, impact
velocities in m/s, times in microseconds, velocities in m/s; the posterior tables keep the paper's
Table IV units (Mbar, cm/us), and the posterior figures convert them (`shockcal.units.user_columns`).
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402

from shockcal.io import atomic_path  # noqa: E402
from shockcal.units import DIMENSIONLESS  # noqa: E402

COLORS = {
    "training": "#8c8c8c",
    "posterior": "#1f5fa8",
    "measurement": "#d62728",
    "model": "#e07b00",
    "reference": "#2b9348",
    "prior": "#d9d9d9",
    "early": "#6a3d9a",
    "late": "#e07b00",
}

RC = {
    "font.size": 9,
    "axes.titlesize": 9,
    "axes.labelsize": 9,
    "xtick.labelsize": 8,
    "ytick.labelsize": 8,
    "legend.fontsize": 8,
    "legend.frameon": False,
    "axes.spines.top": False,
    "axes.spines.right": False,
}

# how an input's name is drawn, where it is not its name
SYMBOLS = {"Delta2": "Δ2", "Delta3": "Δ3"}

# The five features of a trace (SPEC section 4), in plotting order, and the four used in calibration.
FEATURES = {
    "jumpoff": "jump-off",
    "elastic": "elastic plateau",
    "slope1": "slope point 1",
    "slope2": "slope point 2",
    "plastic": "plastic plateau",
}
CALIBRATION_FEATURES = ("v_elastic", "v_plastic", "v_slope1", "v_slope2")

VELOCITY_LABEL = "free-surface velocity (m/s)"
TIME_LABEL = "time (µs)"


def input_symbol(name: str) -> str:
    """How a calibration input is drawn: Delta2 as Δ2, the others by name."""
    return SYMBOLS.get(name, name)


def input_label(name: str, unit: str = "-") -> str:
    """Axis label of a calibration input in `unit` (its display unit): 'A (MPa)', 'Δ2 (GPa)'; 'C'."""
    return input_symbol(name) if unit in DIMENSIONLESS else f"{input_symbol(name)} ({unit})"


def feature_label(column: str) -> str:
    """'v_elastic' -> 'elastic plateau velocity (m/s)'; 't_slope1' -> 'slope point 1 time (µs)'."""
    kind, _, key = column.partition("_")
    quantity = "velocity (m/s)" if kind == "v" else "time (µs)"
    return f"{FEATURES.get(key, key)} {quantity}"


def styled(func):
    """Decorator for figure builders: run them under the project's rcParams (fonts, spines)."""
    from functools import wraps

    @wraps(func)
    def wrapper(*args, **kwargs):
        with plt.rc_context(RC):
            return func(*args, **kwargs)

    return wrapper


def subplots(nrows: int = 1, ncols: int = 1, width: float = 6.0, height: float = 4.0, **kwargs):
    """`plt.subplots` with constrained layout; `axes` is always a 2-D array."""
    return plt.subplots(nrows, ncols, figsize=(width, height), squeeze=False, layout="constrained", **kwargs)


def no_data(ax, message: str) -> None:
    """Turn `ax` into a clearly labelled empty panel saying what is missing."""
    ax.set_xticks([])
    ax.set_yticks([])
    for spine in ax.spines.values():
        spine.set_visible(True)
        spine.set_linestyle(":")
        spine.set_color("0.6")
    ax.text(0.5, 0.5, f"no data\n{message}", transform=ax.transAxes, ha="center", va="center",
            fontsize=8, color="0.35", wrap=True)


def note(ax, text: str, loc: str = "upper left") -> None:
    """A small boxed note inside an axes (shifts, RMSE, counts)."""
    x, ha = (0.03, "left") if "left" in loc else (0.97, "right")
    y, va = (0.97, "top") if "upper" in loc else (0.03, "bottom")
    ax.text(x, y, text, transform=ax.transAxes, ha=ha, va=va, fontsize=7.5,
            bbox={"boxstyle": "round,pad=0.25", "fc": "white", "ec": "0.8", "alpha": 0.9})


def figure_legend(fig, axes, title: str | None = None, ncol: int = 4) -> None:
    """One legend above the panels, with each label once, gathered from every axes."""
    entries = {}
    for ax in np.ravel(axes):
        for handle, label in zip(*ax.get_legend_handles_labels()):
            entries.setdefault(label, handle)
    if entries:
        legend = fig.legend(list(entries.values()), list(entries), loc="outside upper center", ncol=ncol, title=title)
        for handle in legend.legend_handles:
            if isinstance(handle, Line2D):  # faint thin traces get a solid legend line
                handle.set_alpha(1.0)


def save_figure(fig, out_stem: str | Path, formats=("png", "pdf"), dpi: int = 150) -> list[Path]:
    """Write `fig` as `<out_stem>.<fmt>` for every format (atomically), close it, return the paths."""
    out_stem = Path(out_stem)
    out_stem.parent.mkdir(parents=True, exist_ok=True)
    paths = []
    for fmt in formats:
        path = out_stem.with_name(f"{out_stem.name}.{fmt}")
        with atomic_path(path) as tmp:
            fig.savefig(tmp, dpi=dpi, format=fmt)
        paths.append(path)
    plt.close(fig)
    return paths
