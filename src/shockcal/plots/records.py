"""Figure 2: the measured free-surface velocity records, one panel per shot, on the experiment clock.

A shot with a record file configured (observed.records) shows the record and its measured features
(the observed table: extracted from the record, or the published values with observed.source:
published); a shot without one shows only the measured features, and says so.
"""

from __future__ import annotations

import pandas as pd

from shockcal.plots.feature_space import observed_row
from shockcal.plots.style import (
    COLORS,
    FEATURES,
    TIME_LABEL,
    VELOCITY_LABEL,
    figure_legend,
    no_data,
    note,
    styled,
    subplots,
)


def plot_feature_points(ax, measured: pd.Series, dt: float = 0.0, label: str = "measured features") -> None:
    """The five features of a shot as open red circles (times shifted by `dt`)."""
    keys = [k for k in FEATURES if f"t_{k}" in measured.index and f"v_{k}" in measured.index]
    ax.plot([measured[f"t_{k}"] + dt for k in keys], [measured[f"v_{k}"] for k in keys], "o", ms=6,
            mfc="white", mec=COLORS["measurement"], mew=1.8, zorder=6, label=label)


@styled
def fig02_records(records: dict[str, pd.DataFrame | None], observed: pd.DataFrame | None, shots: list[str]):
    """One panel per shot: the record (t_us, v_m_s) when given, the measured features always."""
    fig, axes = subplots(1, len(shots), width=3.6 * len(shots), height=3.4)
    for ax, shot in zip(axes[0], shots):
        record, measured = records.get(shot), observed_row(observed, shot)
        if (record is None or record.empty) and measured is None:
            no_data(ax, f"{shot}: no record and no measured features")
            continue
        if record is not None and not record.empty:
            ax.plot(record["t_us"], record["v_m_s"], color=COLORS["measurement"], lw=1.2, label="measured record")
        else:
            note(ax, "record not configured:\nmeasured features only", loc="lower right")
        if measured is not None:
            plot_feature_points(ax, measured)
        ax.set_title(f"Shot {shot}")
        ax.set_xlabel(f"{TIME_LABEL}, experiment clock")
    axes[0, 0].set_ylabel(VELOCITY_LABEL)
    figure_legend(fig, axes)
    return fig
