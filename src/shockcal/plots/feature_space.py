"""Figures 9 and 10: the calibration features of each shot, training runs against posterior
predictions (through the emulator for 9, through the hydrocode for 10) and the measurement.

One row per shot, one column per calibration feature (elastic plateau, plastic plateau, slope
points 1 and 2, all velocities in m/s): densities of the training runs (grey) and of the posterior
predictions (blue), the measured value as a red line with its +-2 sd band: the likelihood's nominal
observation sd, observed.sd_fraction of the value and the record's read-out sd (`readout_sd_<feature>`
of the observed table, 0 without it) in quadrature (lambda_y = 1).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from shockcal.plots.style import (
    CALIBRATION_FEATURES,
    COLORS,
    feature_label,
    figure_legend,
    no_data,
    note,
    styled,
    subplots,
)


def usable(features: pd.DataFrame | None) -> pd.DataFrame | None:
    """Rows of a features table that did not fail (status column optional); None stays None."""
    if features is None or "status" not in features.columns:
        return features
    return features[features["status"] != "failed"]


def observed_row(observed: pd.DataFrame | None, shot: str) -> pd.Series | None:
    """The measured features of `shot` from the observed table, or None."""
    if observed is None or "shot" not in observed.columns:
        return None
    rows = observed[observed["shot"].astype(str) == shot]
    return None if rows.empty else rows.iloc[0]


def observation_sd(measured: pd.Series, column: str, sd_fraction: float) -> float:
    """The nominal observation sd (m/s) of a measured feature, as the likelihood takes it at lambda_y = 1:
    `sd_fraction` of the value and the row's read-out sd `readout_sd_<column>` (0 if absent) in quadrature."""
    readout = pd.to_numeric(measured.get(f"readout_sd_{column}", 0.0), errors="coerce")
    return float(np.hypot(sd_fraction * abs(float(measured[column])), readout if np.isfinite(readout) else 0.0))


def feature_panel(ax, column, training, predicted, measured, sd):
    """One panel: densities of the training runs and of the predictions (either may be None), the measured
    value with its +-2 sd band (None: not drawn), x limits over all of them (m/s)."""
    finite = [t[column].dropna().to_numpy(float) for t in (training, predicted) if t is not None and column in t.columns]
    finite = [v for v in finite if v.size]
    if measured is not None:
        finite.append(np.array([measured - 3 * sd, measured + 3 * sd]))
    if not finite:
        no_data(ax, f"no {column} values")
        return
    lo, hi = np.percentile(np.concatenate(finite), [0.5, 99.5])
    bins = np.linspace(lo, hi + 1e-9, 31)
    if training is not None and column in training.columns and training[column].notna().any():
        ax.hist(training[column].dropna(), bins=bins, density=True, color=COLORS["training"], alpha=0.5, lw=0,
                label="training runs")
    if predicted is not None and column in predicted.columns and predicted[column].notna().any():
        values = predicted[column].dropna()
        ax.hist(values, bins=bins, density=True, color=COLORS["posterior"], alpha=0.25, lw=0)
        ax.hist(values, bins=bins, density=True, histtype="step", color=COLORS["posterior"], lw=1.5,
                label="posterior predictions")
    if measured is not None:
        ax.axvspan(measured - 2 * sd, measured + 2 * sd, color=COLORS["measurement"], alpha=0.15, lw=0)
        ax.axvline(measured, color=COLORS["measurement"], lw=1.8, label="measured ± 2 sd")
    ax.set_yticks([])
    ax.set_xlim(lo, hi)
    ax.set_xlabel(feature_label(column))


@styled
def feature_space(training: dict, predicted: dict, observed: pd.DataFrame | None, shots: list[str],
                  sd_fraction: float, source: str):
    """Rows of shots, columns of calibration features; `source` names where predictions come from."""
    cols = CALIBRATION_FEATURES
    fig, axes = subplots(len(shots), len(cols), width=2.7 * len(cols), height=2.0 * len(shots) + 0.7)
    for r, shot in enumerate(shots):
        train, pred = usable(training.get(shot)), usable(predicted.get(shot))
        measured = observed_row(observed, shot)
        for c, column in enumerate(cols):
            value = None if measured is None or column not in measured else float(measured[column])
            sd = None if value is None else observation_sd(measured, column, sd_fraction)
            feature_panel(axes[r, c], column, train, pred, value, sd)
        axes[r, 0].set_ylabel(shot, fontsize=10, fontweight="bold")
        missing = [what for what, table in (("training runs", train), (f"predictions ({source})", pred),
                                            ("measurement", measured)) if table is None or len(table) == 0]
        if missing:
            note(axes[r, 0], "missing: " + ", ".join(missing))
    figure_legend(fig, axes, title=f"posterior predictions through the {source}")
    return fig
