"""Figure 6: emulator leave-one-out cross-validation, predicted against simulated, every feature.

Input: the emulator's LOO table in long form, one row per (run, shot, feature) with columns
`shot`, `feature` (e.g. v_elastic), `simulated` and `predicted` (m/s). One panel per shot and
calibration feature, the 1:1 line, and the panel's RMSE.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from shockcal.plots.style import CALIBRATION_FEATURES, COLORS, feature_label, no_data, note, styled, subplots


@styled
def fig06_crossval(cv: pd.DataFrame | None, shots: list[str]):
    """Grid of LOO scatter plots (rows: shots, columns: features) with the overall RMSE in the title."""
    fig, axes = subplots(len(shots), len(CALIBRATION_FEATURES), width=2.6 * len(CALIBRATION_FEATURES),
                         height=2.4 * len(shots) + 0.4)
    if cv is None or cv.empty:
        for ax in axes.flat:
            no_data(ax, "no cross-validation table" if cv is None else "cross-validation table empty")
        return fig
    errors = []
    for r, shot in enumerate(shots):
        for c, feature in enumerate(CALIBRATION_FEATURES):
            ax = axes[r, c]
            rows = cv[(cv["shot"].astype(str) == shot) & (cv["feature"] == feature)]
            if rows.empty:
                no_data(ax, f"no LOO rows for {shot} {feature}")
                continue
            sim, pred = rows["simulated"].to_numpy(float), rows["predicted"].to_numpy(float)
            errors.append(pred - sim)
            lo, hi = np.nanmin([sim.min(), pred.min()]), np.nanmax([sim.max(), pred.max()])
            ax.plot([lo, hi], [lo, hi], color="black", lw=0.8, zorder=1)
            ax.scatter(sim, pred, s=5, color=COLORS["model"], alpha=0.5, lw=0, zorder=2)
            ax.set_aspect("equal", adjustable="datalim")
            note(ax, f"RMSE {np.sqrt(np.nanmean((pred - sim) ** 2)):.1f} m/s")
            ax.set_xlabel(f"simulated {feature_label(feature).replace(' (m/s)', '')} (m/s)", fontsize=7.5)
            if c == 0:
                ax.set_ylabel(f"{shot}\nLOO predicted (m/s)")
    if errors:
        overall = np.sqrt(np.nanmean(np.concatenate(errors) ** 2))
        fig.suptitle(f"Emulator leave-one-out cross-validation: RMSE {overall:.1f} m/s over all features")
    return fig
