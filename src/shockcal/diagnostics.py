"""MCMC convergence diagnostics of Vehtari, Gelman, Simpson, Carpenter, Buerkner (2021).

Rank-normalized split R-hat (the larger of the bulk and folded versions), bulk ESS and tail ESS
(the smaller of the ESS of the 5% and 95% quantile indicators). Each walker of an ensemble is
treated as a chain, as is usual for emcee output. Input arrays are (chains, draws).
"""

from __future__ import annotations

import numpy as np
from scipy import stats

RHAT_LIMIT = 1.05


def _split(x: np.ndarray) -> np.ndarray:
    """Split each chain in halves (dropping a middle draw when the length is odd)."""
    half = x.shape[1] // 2
    return np.concatenate([x[:, :half], x[:, -half:]], axis=0)


def _rank_normalize(x: np.ndarray) -> np.ndarray:
    ranks = stats.rankdata(x, axis=None).reshape(x.shape)
    return stats.norm.ppf((ranks - 0.375) / (x.size + 0.25))


def _rhat(x: np.ndarray) -> float:
    n = x.shape[1]
    within = x.var(axis=1, ddof=1).mean()
    between = n * x.mean(axis=1).var(ddof=1)
    if within == 0:
        return np.nan
    return float(np.sqrt(((n - 1) / n * within + between / n) / within))


def split_rhat(x: np.ndarray) -> float:
    """max(bulk, folded) rank-normalized split R-hat of draws x (chains, draws)."""
    x = _split(np.asarray(x, dtype=float))
    folded = np.abs(x - np.median(x))
    return max(_rhat(_rank_normalize(x)), _rhat(_rank_normalize(folded)))


def _ess(x: np.ndarray) -> float:
    """ESS of (chains, draws) by Geyer's initial monotone sequence on the pooled autocorrelation."""
    m, n = x.shape
    centred = x - x.mean(axis=1, keepdims=True)
    spectrum = np.fft.rfft(centred, n=2 * n, axis=1)
    acov = np.fft.irfft(spectrum * np.conj(spectrum), axis=1)[:, :n] / n
    chain_var = acov[:, 0] * n / (n - 1)
    mean_var = chain_var.mean()
    var_plus = mean_var * (n - 1) / n + (x.mean(axis=1).var(ddof=1) if m > 1 else 0.0)
    if var_plus <= 0:
        return np.nan
    rho = 1.0 - (mean_var - acov.mean(axis=0)) / var_plus
    rho[0] = 1.0
    pairs = rho[: n - n % 2 : 2] + rho[1 : n - n % 2 : 2]
    positive = np.argmax(pairs <= 0) if np.any(pairs <= 0) else len(pairs)
    pairs = np.minimum.accumulate(pairs[:positive])
    tau = max(-1.0 + 2.0 * pairs.sum(), 1.0 / np.log10(m * n))
    return float(m * n / tau)


def ess_bulk(x: np.ndarray) -> float:
    """Bulk effective sample size (rank-normalized split chains)."""
    return _ess(_rank_normalize(_split(np.asarray(x, dtype=float))))


def ess_tail(x: np.ndarray) -> float:
    """Tail effective sample size: the smaller ESS of the 5% and 95% quantile indicators."""
    x = _split(np.asarray(x, dtype=float))
    q05, q95 = np.quantile(x, [0.05, 0.95])
    return min(_ess((x <= q05).astype(float)), _ess((x >= q95).astype(float)))
