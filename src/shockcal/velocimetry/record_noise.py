"""The noise of a measured velocity record: its level, its autocorrelation and replicates of it.

The noise is taken as the residuals of a cubic fit over the record's plastic plateau (from where
its monotone fit reaches 97% of the rise to the end of the analysis window: the longest stretch
without a rise; `shockcal.velocimetry.features.NOISE_PLATEAU_LEVEL`), modelled as a
stationary Gaussian autoregressive process AR(p): Yule-Walker coefficients (scipy's Toeplitz solver)
for p = 1 ... `MAX_ORDER`, p chosen by AIC (n log sigma_p^2 + 2p, sigma_p^2 the innovation
variance). The released VISAR records ring: their residuals oscillate with periods of 7-17 ns, which
AR(1) cannot follow (its autocorrelation decays without oscillating) and AR(2) and above can.

The read-out window (`NoiseModel.half_window_us`) is the lag of the residuals' first autocorrelation
minimum: half an oscillation period, so a window of twice it (centred on a feature time) averages
one whole period out; for white noise it is one sample spacing (the record's time resolution).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.linalg import solve_toeplitz
from scipy.signal import lfilter

MAX_ORDER = 10          # highest AR order tried
MIN_RESIDUALS = 64      # fewest plateau samples the noise is estimated from
TREND_DEGREE = 3        # the polynomial the plateau's residuals are taken from
BURN_IN = 500           # samples an AR replicate runs before it is kept (forgets its zero start)


@dataclass(frozen=True)
class NoiseModel:
    """A record's noise: AR(p) with marginal sd `sd_m_s` and coefficients `ar` (x_k = sum ar_i x_{k-i} + e_k).

    Args:
        sd_m_s: marginal sd of the noise (m/s).
        ar: the AR coefficients (p,).
        half_window_us: the read-out half-window (us): first minimum of the residuals' autocorrelation.
        n_residuals: the plateau samples it was estimated from.
    """

    sd_m_s: float
    ar: tuple
    half_window_us: float
    n_residuals: int

    def simulate(self, n: int, rng: np.random.Generator) -> np.ndarray:
        """n consecutive samples (m/s) of the noise, started `BURN_IN` samples earlier from zero."""
        a = np.concatenate([[1.0], -np.asarray(self.ar)])
        x = lfilter([1.0], a, rng.standard_normal(n + BURN_IN))[BURN_IN:]
        return x * (self.sd_m_s / np.sqrt(ar_variance(self.ar)))


def autocorrelation(x: np.ndarray, max_lag: int) -> np.ndarray:
    """Sample autocorrelation of x at lags 0 ... max_lag (the biased estimator, positive definite)."""
    x = x - x.mean()
    c = np.correlate(x, x, "full")[len(x) - 1:len(x) + max_lag]
    return c / c[0]


def ar_variance(ar) -> float:
    """Marginal variance of an AR process with these coefficients and unit innovations (its impulse
    response's sum of squares, to 1e-12)."""
    a = np.concatenate([[1.0], -np.asarray(ar)])
    n = 1000
    while True:
        h = lfilter([1.0], a, np.r_[1.0, np.zeros(n - 1)])
        if h[-50:] @ h[-50:] < 1e-12 * (h @ h) or n > 10**6:
            return float(h @ h)
        n *= 4


def fit_ar(residuals: np.ndarray) -> np.ndarray:
    """Yule-Walker AR coefficients of `residuals`, the order (1 ... MAX_ORDER) chosen by AIC."""
    rho = autocorrelation(residuals, MAX_ORDER)
    n, best, best_aic = len(residuals), None, np.inf
    for p in range(1, MAX_ORDER + 1):
        phi = solve_toeplitz(rho[:p], rho[1:p + 1])
        aic = n * np.log(max(1.0 - phi @ rho[1:p + 1], 1e-12)) + 2 * p
        if aic < best_aic:
            best, best_aic = phi, aic
    return best


def estimate_noise(t_us: np.ndarray, v_m_s: np.ndarray, plateau_start_us: float, end_us: float) -> NoiseModel:
    """The noise model of a record from its plateau [plateau_start_us, end_us] (us; v in m/s).

    Raises ValueError when the plateau holds fewer than `MIN_RESIDUALS` samples.
    """
    inside = (t_us >= plateau_start_us) & (t_us <= end_us)
    if inside.sum() < MIN_RESIDUALS:
        raise ValueError(f"{int(inside.sum())} samples on the plateau ({plateau_start_us:.3f}-{end_us:.3f} us); "
                         f"at least {MIN_RESIDUALS} are needed to estimate the record's noise")
    t, v = t_us[inside], v_m_s[inside]
    centred = t - t.mean()
    residuals = v - np.polyval(np.polyfit(centred, v, TREND_DEGREE), centred)
    rho = autocorrelation(residuals, len(residuals) // 4)
    rising = np.flatnonzero(np.diff(rho) > 0)
    first_minimum = int(rising[0]) if rising.size else 1
    dt = float(np.median(np.diff(t)))
    return NoiseModel(float(residuals.std()), tuple(fit_ar(residuals).tolist()), max(first_minimum, 1) * dt,
                      int(inside.sum()))
