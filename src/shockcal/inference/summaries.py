"""Summaries of weighted posterior draws: weighted mean, sd and quantiles with their Monte Carlo errors."""

from __future__ import annotations

import numpy as np
import pandas as pd

SUMMARY_QUANTILES = (0.05, 0.5, 0.95)


def summarize(draws, names: list[str]) -> pd.DataFrame:
    """Per parameter: weighted mean, sd, 5/50/95% quantiles with their Monte Carlo standard errors
    (`quantile_mcse` for one run; `quantile_mcse_between` for pooled runs), and the Kish ESS of the weights.

    Args:
        draws: weighted draws (`shockcal.inference.sampler.WeightedDraws`: points (N, d), normalised weights, and
            `replicate`, each draw's run, for pooled runs).
        names: the d parameters' names, in column order.
    """
    w, ess = draws.weights, draws.kish_ess()
    rows = []
    for j, name in enumerate(names):
        x = draws.points[:, j]
        mean = float(np.sum(w * x))
        row = {"parameter": name, "mean": mean, "sd": float(np.sqrt(np.sum(w * (x - mean) ** 2)))}
        errors = (quantile_mcse(x, w, SUMMARY_QUANTILES) if draws.replicate is None
                  else quantile_mcse_between(x, w, draws.replicate, SUMMARY_QUANTILES))
        for p, q, mcse in zip(SUMMARY_QUANTILES, weighted_quantiles(x, w, SUMMARY_QUANTILES), errors):
            row[f"q{round(100 * p):02d}"], row[f"q{round(100 * p):02d}_mcse"] = q, mcse
        rows.append({**row, "ess": ess})
    return pd.DataFrame(rows)


def quantile_mcse(x: np.ndarray, w: np.ndarray, p) -> np.ndarray:
    """Monte Carlo standard error of the p-quantiles of self-normalised weighted draws (weights sum
    to 1): the sd of the weighted CDF at each quantile, sqrt(sum w_i^2 (1[x_i <= q] - p)^2) (the delta
    method; p (1 - p) / N for equal weights), mapped through the weighted quantile function (half the
    width of its image), so no density estimate is needed. It sees where the weight sits: a global
    ESS would not, and in a low-density tail the error of a quantile is large even at a large ESS."""
    p = np.asarray(p, dtype=float)
    w = w / w.sum()
    q = weighted_quantiles(x, w, p)
    a = np.sqrt(np.sum(w[:, None] ** 2 * ((x[:, None] <= q) - p) ** 2, axis=0))
    upper = weighted_quantiles(x, w, np.minimum(p + a, 1.0))
    lower = weighted_quantiles(x, w, np.maximum(p - a, 0.0))
    return 0.5 * (upper - lower)


def quantile_mcse_between(x: np.ndarray, w: np.ndarray, replicate: np.ndarray, p) -> np.ndarray:
    """Monte Carlo standard error of the p-quantiles of R >= 3 pooled independent runs (`replicate`:
    each draw's run; each run's weights summing to 1 / R): the sd of the runs' own quantile estimates
    over sqrt(R). It sees every source of error of a run, the sampler's adaptive bounds included,
    where `quantile_mcse` sees only the weights of one run."""
    runs = np.unique(replicate)
    if len(runs) < 3:
        raise ValueError(f"{len(runs)} runs: the spread of quantiles needs at least 3")
    estimates = np.array([weighted_quantiles(x[replicate == r], w[replicate == r], p) for r in runs])
    return estimates.std(axis=0, ddof=1) / np.sqrt(len(runs))


def weighted_quantiles(x: np.ndarray, w: np.ndarray, q) -> np.ndarray:
    """Quantiles of weighted draws: the inverse of the midpoint-interpolated weighted CDF."""
    order = np.argsort(x)
    cdf = np.cumsum(w[order]) - 0.5 * w[order]
    return np.interp(q, cdf / w.sum(), x[order])


def quantile_moves(before: pd.DataFrame, after: pd.DataFrame) -> tuple[pd.Series, np.ndarray, np.ndarray]:
    """How far each parameter's 5/50/95% points moved between two posterior summaries (`summarize`): the
    parameters of both, then |q_after - q_before| and the combined Monte Carlo SE
    sqrt(mcse_before^2 + mcse_after^2), each (parameters, quantiles) in the summaries' units."""
    both = before.merge(after, on="parameter", suffixes=("_before", "_after"))
    columns = [f"q{round(100 * p):02d}" for p in SUMMARY_QUANTILES]
    moved = np.column_stack([np.abs(both[f"{q}_after"] - both[f"{q}_before"]) for q in columns])
    combined = np.column_stack([np.hypot(both[f"{q}_mcse_before"], both[f"{q}_mcse_after"]) for q in columns])
    return both["parameter"], moved, combined


def quantile_shifts(before: pd.DataFrame, after: pd.DataFrame) -> pd.DataFrame:
    """How far each parameter's 5/50/95% points moved between two posterior summaries (`summarize`), in
    combined Monte Carlo standard errors: |q_after - q_before| / sqrt(mcse_before^2 + mcse_after^2).
    One row per parameter of both (column `parameter`), one column per quantile (q05, q50, q95)."""
    parameters, moved, combined = quantile_moves(before, after)
    with np.errstate(divide="ignore", invalid="ignore"):    # no error and no move: 0; a move without error: inf
        shifts = np.where(combined > 0, moved / combined, np.where(moved > 0, np.inf, 0.0))
    return pd.DataFrame({"parameter": parameters,
                         **{f"q{round(100 * p):02d}": shifts[:, j] for j, p in enumerate(SUMMARY_QUANTILES)}})


def posterior_settled(before: pd.DataFrame, after: pd.DataFrame, threshold: float,
                      box_widths: dict[str, float] | None = None, box_fraction: float = 0.0) -> bool:
    """The stopping rule of a sequential study: no 5/50/95% point of any parameter moved by `threshold`
    combined Monte Carlo standard errors or more, except a point that moved by less than `box_fraction`
    of its parameter's box width (`box_widths`: summary parameter name -> width in the summaries' units;
    a parameter without one is held to the Monte Carlo SE alone). With a threshold of 0 any move counts
    but one under the box fraction; both 0 never settle."""
    if threshold <= 0 and box_fraction <= 0:
        return False
    parameters, moved, combined = quantile_moves(before, after)
    still = (moved > 0) & (moved >= threshold * combined)
    if box_fraction > 0:
        width = parameters.map(box_widths or {}).to_numpy(float)[:, None]      # NaN: no box, never settled by it
        still &= ~(moved < box_fraction * width)
    return not still.any()
