"""The measured features against the training runs (prior predictive): a row per shot, a column per
calibration feature (m/s). Densities of the training runs (grey), the measured value with its +-2 sd
band (red: the likelihood's nominal observation sd, `feature_space.observation_sd`), and the band a
measurement must lie in before a calibration starts (dashed: the training runs' range widened by
`shockcal.inference.training_range.RANGE_MARGIN` of its width on each side). A feature outside it is
named in its panel: the calibration stops on it unless `checks.features_in_training_range` is false.
"""

from __future__ import annotations

import pandas as pd

from shockcal.inference.training_range import outside_training_range, training_ranges
from shockcal.plots.feature_space import feature_panel, observation_sd, observed_row, usable
from shockcal.plots.style import CALIBRATION_FEATURES, COLORS, figure_legend, note, styled, subplots


@styled
def measured_against_training(training: dict, observed: pd.DataFrame | None, shots: list[str], sd_fraction: float):
    """Rows of shots, columns of calibration features.

    Args:
        training: shot -> its training features table (m/s; failed runs are left out), or None.
        observed: the observed features table (a row per shot, m/s), or None.
        shots: the shots, in row order.
        sd_fraction: the observation sd's share of each measured feature (`observed.sd_fraction`).
    """
    cols = CALIBRATION_FEATURES
    fig, axes = subplots(len(shots), len(cols), width=2.7 * len(cols), height=2.0 * len(shots) + 0.7)
    for r, shot in enumerate(shots):
        train, measured = usable(training.get(shot)), observed_row(observed, shot)
        ranges = training_ranges({shot: train}, cols).get(shot, {}) if train is not None and len(train) else {}
        for c, column in enumerate(cols):
            ax = axes[r, c]
            value = None if measured is None or column not in measured else float(measured[column])
            sd = None if value is None else observation_sd(measured, column, sd_fraction)
            feature_panel(ax, column, train, None, value, sd)
            if column not in ranges:
                continue
            low, high = ranges[column].band()
            for edge in (low, high):
                ax.axvline(edge, color=COLORS["training"], ls="--", lw=1.0, label="accepted band")
            shown = ax.get_xlim()
            pad = 0.03 * (high - low)
            ax.set_xlim(min(shown[0], low - pad), max(shown[1], high + pad))
            if value is not None and outside_training_range({shot: {column: value}}, {shot: ranges}):
                ax.set_title("outside the training runs", color=COLORS["measurement"],
                             fontsize=8)
        axes[r, 0].set_ylabel(shot, fontsize=10, fontweight="bold")
        missing = [what for what, table in (("training runs", train), ("measurement", measured))
                   if table is None or len(table) == 0]
        if missing:
            note(axes[r, 0], "missing: " + ", ".join(missing))
    figure_legend(fig, axes, title="measured features against the training runs (prior predictive)")
    return fig
