"""Figures 11-13: free-surface velocity histories of one shot: training runs, posterior runs through
the hydrocode, and the measurement shifted in time.

The measurement's clock is unrelated to the simulation's (SPEC section 1; the paper shifted the
records by 0.08, 0.45 and 2.75 us). The shift is estimated here, not copied: the median simulated
feature times minus the measured ones, averaged over the five features, and stated in the figure.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from matplotlib import patheffects

from shockcal.plots.feature_space import usable
from shockcal.plots.records import plot_feature_points
from shockcal.plots.style import COLORS, FEATURES, TIME_LABEL, VELOCITY_LABEL, figure_legend, no_data, styled, subplots

TIME_COLUMNS = tuple(f"t_{key}" for key in FEATURES)


def estimate_time_shift(observed: pd.Series | None, simulated: pd.DataFrame | None) -> float | None:
    """Time (us) to add to the measured clock so its features line up with the simulated ones."""
    simulated = usable(simulated)
    if observed is None or simulated is None or simulated.empty:
        return None
    columns = [c for c in TIME_COLUMNS if c in simulated.columns and c in observed.index]
    offsets = [float(simulated[c].median()) - float(observed[c]) for c in columns]
    offsets = [o for o in offsets if np.isfinite(o)]
    return float(np.mean(offsets)) if offsets else None


def _traces(ax, sims: pd.DataFrame | None, color: str, label: str, limit: int, lw: float, alpha: float, seed: int):
    """Draw up to `limit` traces (seeded choice); return how many were drawn."""
    sims = usable(sims)
    if sims is None or sims.empty:
        return 0
    if len(sims) > limit:
        sims = sims.sample(limit, random_state=seed)
    for i, (t, v) in enumerate(zip(sims["t_us"], sims["v_m_s"])):
        ax.plot(np.asarray(t), np.asarray(v), color=color, lw=lw, alpha=alpha, label=label if i == 0 else None)
    return len(sims)


@styled
def fig_history(shot: str, training: pd.DataFrame | None, posterior: pd.DataFrame | None,
                observed: pd.Series | None, record: pd.DataFrame | None, shift: float | None,
                n_training: int = 100, seed: int = 0):
    """Velocity histories of `shot`; `record` (t_us, v_m_s) and `observed` features are shifted by `shift`."""
    fig, axes = subplots(1, 1, width=7.0, height=4.3)
    ax = axes[0, 0]
    n_train = _traces(ax, training, COLORS["training"], "training runs", n_training, 0.6, 0.35, seed)
    n_post = _traces(ax, posterior, COLORS["posterior"], "posterior runs", 10**9, 0.7, 0.45, seed)
    if n_train + n_post == 0 and observed is None and record is None:
        no_data(ax, f"{shot}: no simulated traces and no measurement")
        return fig
    outline = [patheffects.withStroke(linewidth=3.2, foreground="white")]
    dt = shift or 0.0
    if record is not None and not record.empty:
        ax.plot(record["t_us"] + dt, record["v_m_s"], color=COLORS["measurement"], lw=1.6, zorder=5,
                path_effects=outline, label="measured record")
    if observed is not None:
        plot_feature_points(ax, observed, dt)
    total = 0 if training is None else len(usable(training))
    counts = f"{n_train} training runs" + (f" (of {total})" if n_train < total else "") + f", {n_post} posterior runs"
    if observed is None and record is None:
        timing = "no measurement for this shot"
    elif shift is None:
        timing = "measurement not shifted (no simulated features to align with)"
    else:
        timing = f"measurement shifted by {shift:+.3f} µs (estimated)"
    _time_window(ax, training, posterior, observed, dt)
    ax.set_xlabel(TIME_LABEL)
    ax.set_ylabel(VELOCITY_LABEL)
    ax.set_title(f"Shot {shot}: free-surface velocity\n{counts}; {timing}")
    figure_legend(fig, axes)
    return fig


def _time_window(ax, training, posterior, observed, dt):
    """From a little before the earliest jump-off to the end of the simulated traces."""
    starts, ends = [], []
    for sims in (usable(training), usable(posterior)):
        if sims is not None and not sims.empty:
            for t, v in zip(sims["t_us"], sims["v_m_s"]):
                t, v = np.asarray(t), np.asarray(v)
                if v.size and np.nanmax(v) > 0:
                    starts.append(t[np.argmax(v > 0.02 * np.nanmax(v))])
                    ends.append(t[-1])
    if observed is not None and "t_jumpoff" in observed.index:
        starts.append(observed["t_jumpoff"] + dt)
    if starts:
        left = min(starts) - 0.2
        right = max(ends) if ends else left + 2.0
        ax.set_xlim(left, right)
