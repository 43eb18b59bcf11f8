"""When the release from the flyer's back reaches the free surface, on a record and on posterior-predictive
runs (the strength-law comparison: does any law reach 104S's release later than Johnson-Cook's runs?).

A trace's release time is the first sample after its plastic plateau's feature time (`t_plastic`, the
extractor's) at which the velocity falls below the plateau's velocity (`v_plastic`) minus a margin, in us
after the trace's own arrival (`shockcal.velocimetry.features.detect_arrival`), so a record and a simulation compare
without aligning their clocks. The margin (20 m/s) is above the records' dips on the plateau (up to about
11 m/s on 105S and 106S within 0.3 us of t_plastic) and well below the release's fall (hundreds of m/s).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from shockcal.velocimetry.features import detect_arrival

RELEASE_MARGIN_M_S = 20.0
RELEASE_COLUMNS = ["model", "shot", "release_record_us", "release_predicted_median_us", "release_predicted_q05_us",
                   "release_predicted_q95_us", "shift_us", "n_runs", "n_without_release"]


def release_after_arrival_us(t_us, v_m_s, t_plastic_us: float, v_plastic_m_s: float,
                             margin_m_s: float = RELEASE_MARGIN_M_S) -> float:
    """The release's arrival on one trace, us after the trace's arrival; NaN when the trace ends before
    falling below v_plastic - margin after t_plastic.

    Args:
        t_us, v_m_s: the trace (us, increasing; m/s).
        t_plastic_us, v_plastic_m_s: its plastic plateau's feature time (the trace's clock) and velocity.
        margin_m_s: how far below the plateau the velocity must fall.
    """
    t, v = np.asarray(t_us, dtype=float), np.asarray(v_m_s, dtype=float)
    below = (t > t_plastic_us) & (v < v_plastic_m_s - margin_m_s)
    if not below.any():
        return math.nan
    return float(t[np.argmax(below)] - detect_arrival(t, v))


def release_row(model: str, shot: str, record_us: float, predicted_us) -> dict:
    """One row of RELEASE_COLUMNS: the record's release, the predictive runs' median and 5/95% (those that
    reach a release), shift_us = median - record (negative: the law's runs release early)."""
    predicted = np.asarray(predicted_us, dtype=float)
    found = predicted[np.isfinite(predicted)]
    q05, q50, q95 = np.quantile(found, [0.05, 0.5, 0.95]) if found.size else (math.nan,) * 3
    return {"model": model, "shot": shot, "release_record_us": record_us, "release_predicted_median_us": q50,
            "release_predicted_q05_us": q05, "release_predicted_q95_us": q95, "shift_us": q50 - record_us,
            "n_runs": int(found.size), "n_without_release": int(predicted.size - found.size)}


def predicted_releases_us(simulations: pd.DataFrame, features: pd.DataFrame,
                          margin_m_s: float = RELEASE_MARGIN_M_S) -> pd.Series:
    """Each successful run's release (us after its arrival), by run: `simulations` (run, status, t_us, v_m_s)
    joined on run with its `features` (run, status, t_plastic, v_plastic)."""
    ok = features[features["status"] == "ok"].set_index("run")
    runs = simulations[(simulations["status"] == "ok") & simulations["run"].isin(ok.index)]
    return pd.Series({int(r.run): release_after_arrival_us(r.t_us, r.v_m_s, ok.at[r.run, "t_plastic"],
                                                            ok.at[r.run, "v_plastic"], margin_m_s)
                      for r in runs.itertuples()}, dtype=float)
