"""The strength laws compared: log evidence per law, and one page per law of its posterior
predictive runs against the records, past the analysis window."""

from __future__ import annotations

from collections.abc import Mapping
from typing import NamedTuple

import numpy as np
import pandas as pd

from shockcal.plots.style import COLORS, VELOCITY_LABEL, figure_legend, no_data, styled, subplots
from shockcal.velocimetry.features import detect_arrival


@styled
def evidence_figure(table: pd.DataFrame):
    """log Z per law (rows of the evidence table, `shockcal.campaign.model_comparison.COLUMNS`) with +-2 sd bars, the
    box-halved value (with +-2 sd) and the box-doubled lower bound marked beside it."""
    fig, axes = subplots(1, 1, width=6.0, height=0.9 + 0.55 * len(table))
    ax = axes[0, 0]
    y = np.arange(len(table))[::-1]
    ax.errorbar(table["log_z"], y, xerr=2 * table["log_z_sd"], fmt="o", color=COLORS["posterior"], capsize=3,
                label="log Z (±2 sd)")
    ax.errorbar(table["log_z_box_half"], y - 0.2, xerr=2 * table["log_z_box_half_sd"].fillna(0), fmt="v",
                color=COLORS["model"], capsize=3, label="box halved (±2 sd)")
    ax.plot(table["log_z_box_double"], y + 0.2, ">", color=COLORS["reference"],
            label="box doubled (lower bound)")
    ax.set_yticks(y, table["model"])
    ax.set_ylim(-0.6, len(table) - 0.4)
    values = np.concatenate([table[c].to_numpy(float) for c in ("log_z", "log_z_box_half", "log_z_box_double")])
    values = np.concatenate([values[np.isfinite(values)], table["log_z"] + 2 * table["log_z_sd"],
                             table["log_z"] - 2 * table["log_z_sd"]])
    ax.set_xlim(values.min() - 1.5, values.max() + 1.5)      # a wider sd bar is cut at the axes
    for row_y, half in zip(y, table["log_z_box_half"]):
        if half == -np.inf:
            ax.annotate("box halved: no posterior draw inside (-inf)", (0.01, row_y - 0.2), xycoords=("axes fraction", "data"),
                        va="center", fontsize=7, color=COLORS["model"])
    ax.set_xlabel("log evidence")
    ax.set_title("log Z per law; with the box of its own and shear-modulus parameters\nhalved and doubled "
                 "about its centre (bars cut at the axes)")
    figure_legend(fig, axes, ncol=3)
    return fig


class ShotPredictions(NamedTuple):
    """One shot of one law: the record (t_us, v_m_s; None without one), the predictive runs (run, status,
    t_us, v_m_s), the analysis window's end after arrival (us) and the record's release after arrival (us)."""

    record: pd.DataFrame | None
    runs: pd.DataFrame | None
    window_after_arrival_us: float
    release_record_us: float


def _after_arrival(t, v):
    t, v = np.asarray(t, dtype=float), np.asarray(v, dtype=float)
    return t - detect_arrival(t, v), v


@styled
def predictive_figure(model: str, shots: Mapping[str, ShotPredictions]):
    """One panel per shot: the law's posterior-predictive traces and the record, each in us after its own
    arrival, over the whole simulated record; the analysis window's end and the record's release marked."""
    fig, axes = subplots(len(shots), 1, width=7.0, height=0.8 + 2.4 * len(shots))
    for ax, (shot, data) in zip(axes[:, 0], shots.items()):
        runs = None if data.runs is None else data.runs[data.runs["status"] == "ok"]
        if (runs is None or runs.empty) and data.record is None:
            no_data(ax, f"{shot}: no predictive runs and no record")
            continue
        ends = []
        for i, r in enumerate(() if runs is None else runs.itertuples()):
            t, v = _after_arrival(r.t_us, r.v_m_s)
            ends.append(t[-1])
            ax.plot(t, v, color=COLORS["posterior"], lw=0.7, alpha=0.4, label="posterior runs" if i == 0 else None)
        if data.record is not None:
            t, v = _after_arrival(data.record["t_us"], data.record["v_m_s"])
            keep = t <= (max(ends) if ends else t[-1])
            ax.plot(t[keep], v[keep], color=COLORS["measurement"], lw=1.4, label="measured record")
        ax.axvline(data.window_after_arrival_us, color="0.3", ls="--", lw=0.9, label="analysis window's end")
        if np.isfinite(data.release_record_us):
            ax.axvline(data.release_record_us, color=COLORS["measurement"], ls=":", lw=1.1,
                       label="record's release")
        ax.set_xlim(left=-0.2)
        ax.set_ylabel(VELOCITY_LABEL)
        ax.set_title(f"Shot {shot}: {0 if runs is None else len(runs)} posterior runs")
    axes[-1, 0].set_xlabel("time after the trace's arrival (µs)")
    figure_legend(fig, axes, title=f"{model}: posterior predictive runs past the analysis window")
    return fig
