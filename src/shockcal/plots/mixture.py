"""Figures of the feature extractor on one trace: 4 (the features), 5 (early/late mixture split),
15 (the probability-integral-transform construction).

The numbers come from the project's extractor (`shockcal.velocimetry.features.extract`, whose `Extraction`
keeps the window, the standardized trace, the PIT samples, the mixture and its early/late split). The trace is the first shot's
measured record when one is configured, else its first usable simulated training run.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from shockcal.errors import InputError
from shockcal.plots.feature_space import usable
from shockcal.plots.records import plot_feature_points
from shockcal.plots.style import COLORS, FEATURES, TIME_LABEL, VELOCITY_LABEL, no_data, styled, subplots


def pick_trace(record: pd.DataFrame | None, simulations: pd.DataFrame | None, shot: str):
    """(trace table with t_us, v_m_s; description) or (None, reason)."""
    if record is not None and not record.empty:
        return record[["t_us", "v_m_s"]], f"measured record, shot {shot}"
    runs = usable(simulations)
    if runs is None or runs.empty:
        return None, f"no record and no simulated run of shot {shot}"
    first = runs.sort_values("run").iloc[0]
    trace = pd.DataFrame({"t_us": np.asarray(first["t_us"], float), "v_m_s": np.asarray(first["v_m_s"], float)})
    return trace, f"simulated training run {int(first['run'])}, shot {shot}"


@dataclass(frozen=True)
class TraceExtraction:
    """A whole trace (times in us, velocities in m/s) and the extractor's account of it."""

    t: np.ndarray
    v: np.ndarray
    ex: object  # shockcal.velocimetry.features.Extraction

    @property
    def features(self) -> pd.Series:
        return pd.Series(self.ex.features)


def extract_view(trace: pd.DataFrame, settings) -> TraceExtraction:
    """Run the project's extractor on `trace` with the shot's `ExtractorSettings`."""
    from shockcal.velocimetry.features import extract

    t, v = trace["t_us"].to_numpy(float), trace["v_m_s"].to_numpy(float)
    ex = extract(t, v, settings)
    return TraceExtraction(t, v, ex)


def _view_or_note(trace, label, settings):
    """(view, None) or (None, reason) when there is no trace or the extractor refuses it."""
    if trace is None:
        return None, label
    try:
        return extract_view(trace, settings), None
    except (InputError, ValueError) as exc:
        return None, f"extractor failed on {label}: {exc}"


def _mixture_pdf(view: TraceExtraction, grid, which):
    from scipy.stats import norm

    mix = view.ex.mixture
    return sum(w * norm.pdf(grid, m, s) for w, m, s, e in zip(mix.weights, mix.means, mix.sds, view.ex.early)
               if which is None or e == which)


@styled
def fig04_trace_features(trace, label: str, settings):
    """The five features marked on the trace, the analysis window shaded."""
    fig, axes = subplots(1, 1, width=6.5, height=4.0)
    ax = axes[0, 0]
    view, problem = _view_or_note(trace, label, settings)
    if view is None:
        no_data(ax, problem)
        return fig
    ax.axvspan(*view.ex.window, color=COLORS["prior"], alpha=0.6, lw=0, label="analysis window")
    ax.plot(view.t, view.v, color="black", lw=1.2, label="trace")
    plot_feature_points(ax, view.features, label="features")
    for key, name in FEATURES.items():
        offset = (0, 9) if key == "plastic" else (8, -4)  # the plastic plateau's label sits above the flat trace
        ax.annotate(name, (view.features[f"t_{key}"], view.features[f"v_{key}"]), xytext=offset,
                    textcoords="offset points", fontsize=8, color=COLORS["measurement"],
                    ha="center" if key == "plastic" else "left")
    lo, hi = view.ex.window
    ax.set_xlim(lo - 0.1 * (hi - lo), hi + 0.1 * (hi - lo))
    ax.set_xlabel(TIME_LABEL)
    ax.set_ylabel(VELOCITY_LABEL)
    ax.set_title(label)
    ax.legend(loc="lower right")
    return fig


@styled
def fig05_mixture_split(trace, label: str, settings):
    """PIT samples with the fitted mixture, components split into early and late at the cut-off."""
    fig, axes = subplots(1, 1, width=6.5, height=4.0)
    ax = axes[0, 0]
    view, problem = _view_or_note(trace, label, settings)
    if view is None:
        no_data(ax, problem)
        return fig
    grid = np.linspace(*view.ex.window, 600)
    ax.hist(view.ex.samples, bins=80, range=view.ex.window, density=True, color=COLORS["training"], alpha=0.45, lw=0,
            label=f"{len(view.ex.samples):,} PIT samples")
    ax.plot(grid, _mixture_pdf(view, grid, None), color="black", lw=1.2, label="mixture (5 components)")
    ax.fill_between(grid, _mixture_pdf(view, grid, True), color=COLORS["early"], alpha=0.45, lw=0,
                    label=f"early components ({int(view.ex.early.sum())})")
    ax.fill_between(grid, _mixture_pdf(view, grid, False), color=COLORS["late"], alpha=0.35, lw=0,
                    label=f"late components ({int((~view.ex.early).sum())})")
    ax.axvline(view.ex.cutoff_us, color="black", ls="--", lw=1, label=f"cut-off c = {view.ex.cutoff_us:.3f} µs")
    ax.set_xlim(view.ex.window)
    ax.set_xlabel(TIME_LABEL)
    ax.set_ylabel("density (1/µs)")
    ax.legend(loc="upper right")
    ax.set_title(label)
    return fig


@styled
def fig15_pit_construction(trace, label: str, settings, n_arrows: int = 9):
    """The standardized trace read as a CDF: uniform draws mapped through its inverse to times."""
    fig, axes = subplots(2, 1, width=6.0, height=5.6, sharex=True, gridspec_kw={"height_ratios": [3, 2]})
    top, bottom = axes[:, 0]
    view, problem = _view_or_note(trace, label, settings)
    if view is None:
        for ax in (top, bottom):
            no_data(ax, problem)
        return fig
    top.plot(view.ex.t_window, view.ex.cdf_window, color="black", lw=1.4, label="standardized, monotone trace y(t)")
    for u in (np.arange(n_arrows) + 0.5) / n_arrows:
        t_u = float(np.interp(u, view.ex.cdf_window, view.ex.t_window))
        top.annotate("", xy=(t_u, u), xytext=(view.ex.window[0], u),
                     arrowprops={"arrowstyle": "->", "color": COLORS["model"], "lw": 0.9})
        top.annotate("", xy=(t_u, 0), xytext=(t_u, u),
                     arrowprops={"arrowstyle": "->", "color": COLORS["model"], "lw": 0.9, "ls": ":"})
    top.plot([], [], color=COLORS["model"], label="u ~ U(0, 1) mapped to t = y⁻¹(u)")
    top.set_ylabel("standardized velocity y")
    top.set_ylim(0, 1.02)
    top.legend(loc="lower right")
    top.set_title(label)
    bottom.hist(view.ex.samples, bins=80, range=view.ex.window, density=True, color=COLORS["model"], alpha=0.5, lw=0,
                label=f"{len(view.ex.samples):,} samples t = y⁻¹(u)")
    bottom.set_xlim(view.ex.window)
    bottom.set_xlabel(TIME_LABEL)
    bottom.set_ylabel("density (1/µs)")
    bottom.legend(loc="upper right")
    return fig
