"""Features of a free-surface velocity trace by the Gaussian-mixture CDF method (SPEC section 4).

1. Baseline and arrival: the baseline is the median of the trace before the rise and the noise
   level its robust spread; the arrival is the first time the trace exceeds the baseline by
   `ARRIVAL_FRACTION` of the total rise (or 5 noise sd, whichever is larger). A trace exactly at
   rest before the rise (a simulation: zero baseline, zero spread; a record's constant pre-trigger
   offset is not zero) uses `QUIET_ARRIVAL_FRACTION` instead, so that a
   weak precursor (small A, or m near 0: a few m/s ahead of a 500 m/s plastic wave) is the arrival
   rather than the plastic wave behind it.
2. Analysis window: from `PRE_ARRIVAL_US` before the arrival to `window_after_arrival_us` after it
   (per shot in config; it must end before the release from the flyer's back reaches the free
   surface). Measured records carry pre-trigger content and a baseline offset: both are outside
   the window or removed by the standardization below.
3. The windowed trace is standardized to run from 0 to 1, made monotone and read as a CDF (a
   noise-free trace: the running maximum; a noisy one, `is_noisy`: its isotonic regression, which does
   not climb to the noise peaks); 10,000 samples are drawn by the probability integral transform: stratified uniform
   draws u_i = (i + 1/2)/N (no random numbers) mapped through the inverse CDF, linear interpolation
   of (y, t). The samples move smoothly with the trace, so neighbouring runs get neighbouring samples.
   Their distribution is known exactly: uniform between consecutive (t, y) pairs where y rises.
4. A k = 5 Gaussian mixture is fitted by EM to that exact distribution, the limit of infinitely many
   samples (`fit_mixture_exact`, `shockcal.velocimetry.mixture_fit`: Gauss-Legendre quadrature over its uniform
   pieces), from `MIXTURE_STARTS` fixed starts made from the samples as scikit-learn made them (means
   at the samples' k quantiles, then k-means starts seeded 0, 1, ...), each run to convergence
   (`MIXTURE_TOL`, far below scikit-learn's default 1e-3, which stops on a plateau of the
   likelihood); the start of highest likelihood is kept. `extract(..., method="pit")` keeps the
   fit to the samples themselves (`fit_mixture`, scikit-learn), 30-90 times slower. The features are a deterministic function of
   the trace (no seed); a perturbation of 1e-6 of the rise moves them by 0.005 m/s or ns (median over
   hydrocode traces), more only where two EM optima nearly tie (docs/features.md, "Stability").
   Components with mu + 2 sigma < c,
   c = arrival + `cutoff_after_arrival_us`, form the early (elastic) mixture, the rest the late one.
   A trace with a single wave (elastic only at large A, or a precursor merged with the plastic
   rise) puts every component on one side: then the latest (resp. earliest) component is taken as
   the late (early) mixture, so every run of the design box has features, as FLAG's had; the slope
   times are kept at or after the elastic time (FLAG's single-wave runs have all points on the top),
   and a stand-in early component's jump-off and elastic times inside [window start, cut-off].
5. Times: jump-off = 0.01 quantile and elastic plateau = 0.99 quantile of the early mixture; slope
   points = 0.1 and 0.9 quantiles of the late mixture; plastic plateau = the time the standardized
   trace reaches 0.995. Each velocity is the trace's value at that time (a noisy trace: the value of a
   least-squares line over the record's read-out window, `shockcal.velocimetry.record_noise`; the slope
   points over at most `RISE_SHARE` of the plastic rise time, `slope_half_window_us`).
6. A noisy trace's read-out error: the spread of its features over replicates of its noise
   (`readout_replicates`, `readout_sd`), which the calibration adds to the 1% observation sd.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from scipy import optimize, stats
from scipy.optimize import isotonic_regression
from scipy.signal import savgol_filter

from shockcal.velocimetry.columns import COLUMNS, FEATURES
from shockcal.velocimetry.settings import ExtractorSettings

if TYPE_CHECKING:
    import pandas as pd

log = logging.getLogger("shockcal.velocimetry.features")
ARRIVAL_FRACTION = 0.02
QUIET_ARRIVAL_FRACTION = 0.002
NOISE_MULTIPLE = 5.0
PRE_ARRIVAL_US = 0.05
PLASTIC_LEVEL = 0.995
NOISE_FLOOR = 1e-4          # a trace is noisy (read robustly) above this robust sd before arrival, share of its range
NOISE_PLATEAU_LEVEL = 0.97  # a record's noise is estimated where its monotone fit has passed this level
RISE_SHARE = 0.15          # the slope points' read-out half-window at most this share of the plastic rise time
MIXTURE_STARTS = 3         # EM starts: quantile-spaced means, then k-means seeded 0, 1, ...
MIXTURE_TOL = 1e-5         # EM stops when the mean log-likelihood gains less than this
MIXTURE_MAX_ITER = 1000
DEFAULT_SETTINGS = ExtractorSettings()     # the config's defaults (a frozen model: one for every call)


class FeatureError(ValueError):
    """The trace has no features (no rise, no elastic or plastic part): the run is marked failed."""


@dataclass
class Mixture:
    """A 1-D Gaussian mixture (weights normalized), with its CDF and quantiles."""

    weights: np.ndarray
    means: np.ndarray
    sds: np.ndarray

    def cdf(self, x):
        return np.sum(self.weights * stats.norm.cdf((np.atleast_1d(x)[:, None] - self.means) / self.sds), axis=1)

    def quantile(self, p: float) -> float:
        lo, hi = (self.means - 10 * self.sds).min(), (self.means + 10 * self.sds).max()
        return optimize.brentq(lambda x: self.cdf(x)[0] - p, lo, hi, xtol=1e-9)

    def subset(self, mask) -> Mixture:
        w = self.weights[mask]
        return Mixture(w / w.sum(), self.means[mask], self.sds[mask])


@dataclass
class Extraction:
    """Everything the extractor computed for one trace (the figures show the intermediate steps)."""

    features: dict           # column -> value (times us, velocities m/s)
    arrival_us: float
    cutoff_us: float
    window: tuple            # (start, end) us
    t_window: np.ndarray
    cdf_window: np.ndarray   # standardized, monotone trace on t_window
    samples: np.ndarray      # PIT samples (us)
    mixture: Mixture
    early: np.ndarray        # boolean mask of early components
    noise: object = None     # the record's NoiseModel (shockcal.velocimetry.record_noise) when read robustly, else None
    slope_half_window_us: float = 0.0   # the slope points' read-out half-window (`slope_half_window_us`)


def baseline_and_noise(t: np.ndarray, v: np.ndarray) -> tuple[float, float]:
    """Median and robust sd of the trace before it first reaches half its maximum rise."""
    half = np.argmax(v - v[0] >= 0.5 * (v.max() - v[0]))
    quiet = v[: max(half // 2, 5)]
    baseline = float(np.median(quiet))
    noise = float(1.4826 * np.median(np.abs(quiet - baseline)))
    return baseline, noise


def detect_arrival(t: np.ndarray, v: np.ndarray) -> float:
    """First time the trace rises above its baseline by a small share of the rise (or the noise)."""
    baseline, noise = baseline_and_noise(t, v)
    rise = v.max() - baseline
    at_rest = baseline == 0.0 and noise == 0.0
    fraction = QUIET_ARRIVAL_FRACTION if at_rest else ARRIVAL_FRACTION
    threshold = max(fraction * rise, NOISE_MULTIPLE * noise)
    if rise <= 2 * threshold or rise <= 0:
        raise FeatureError(f"no rise above the baseline (rise {rise:.3g} m/s, noise {noise:.3g} m/s)")
    return float(t[np.argmax(v - baseline > threshold)])


def extract(t, v, settings: ExtractorSettings = DEFAULT_SETTINGS, method: str = "exact",
            robust: bool | None = None) -> Extraction:
    """Run the extractor on one trace; raises FeatureError when it cannot.

    Args:
        t: times (us), increasing.
        v: free-surface velocity (m/s) at those times.
        settings: the analysis window, elastic cut-off and mixture size (`ExtractorSettings`).
        method: "exact" fits the mixture to the standardized trace's exact CDF (`fit_mixture_exact`,
            from starts made from the n_samples PIT samples); "pit" (the reference, 30-90 times slower)
            fits it by scikit-learn's EM to the samples (`fit_mixture`). Both draw the samples: the
            figures show them.
        robust: the noisy-trace read (isotonic monotone fit, velocities from local linear fits over the
            record's noise window, `shockcal.velocimetry.record_noise`) or the noise-free one (running maximum,
            velocities interpolated between two samples). None (default): robust when the trace is
            noisy before its arrival (`is_noisy`), so simulated traces are read as before.

    Returns:
        An `Extraction`: the ten features (times us, velocities m/s) and the intermediate steps.
    """
    t, v = np.asarray(t, dtype=float), np.asarray(v, dtype=float)
    bad = ~(np.isfinite(t) & np.isfinite(v))
    if bad.any():
        raise FeatureError(f"{int(bad.sum())} non-finite values in the trace (first at index {int(np.argmax(bad))})")
    arrival = detect_arrival(t, v)
    start, end = arrival - PRE_ARRIVAL_US, arrival + settings.window_after_arrival_us
    robust = is_noisy(v[(t >= start) & (t < arrival)], np.ptp(v)) if robust is None else robust
    if end > t[-1]:
        raise FeatureError(f"trace ends at {t[-1]:.3f} us, before the analysis window ({end:.3f} us)")
    inside = (t >= start) & (t <= end)
    tw, vw = t[inside], v[inside]
    y = monotone_cdf(vw, robust)
    rising = np.diff(y, prepend=-1.0) > 0
    n = settings.n_samples
    samples = np.interp((np.arange(n) + 0.5) / n, y[rising], tw[rising])
    if method == "exact":
        mixture = fit_mixture_exact(tw, y, samples, settings.n_components)
    elif method == "pit":
        mixture = fit_mixture(samples, settings.n_components)
    else:
        raise ValueError(f"unknown mixture fit {method!r}: 'exact' or 'pit'")
    cutoff = arrival + settings.cutoff_after_arrival_us
    early = split_early(mixture, cutoff)
    times = feature_times(tw, y, mixture, early, cutoff)
    noise = record_noise(t, v, float(tw[np.argmax(y >= NOISE_PLATEAU_LEVEL)]), end) if robust else None
    half_window = 0.0 if noise is None else noise.half_window_us
    slope_window = slope_half_window_us(half_window, times)
    features = feature_values(t, v, times, half_window, slope_window)
    return Extraction(features, arrival, cutoff, (start, end), tw, y, samples, mixture, early, noise, slope_window)


def is_noisy(v_before_arrival: np.ndarray, range_m_s: float) -> bool:
    """Whether the trace just before its arrival (the window's first `PRE_ARRIVAL_US`) has a robust sd
    (1.4826 x MAD) above `NOISE_FLOOR` of its range: a record's (0.8-2.3 m/s, 2.5e-3 to 4.7e-3 of it),
    not a simulation's (at rest: 0) nor an analytic trace's."""
    return float(stats.median_abs_deviation(v_before_arrival, scale="normal")) > NOISE_FLOOR * range_m_s


def monotone_cdf(v_window: np.ndarray, robust: bool) -> np.ndarray:
    """The windowed trace standardized to run from 0 to 1 and made non-decreasing: its isotonic
    regression (the least-squares monotone fit, scipy) when `robust`, else the running maximum of
    (v - min) / (max - min), which on a noisy record climbs to the highest noise peak."""
    if robust:
        fit = isotonic_regression(v_window).x
        return (fit - fit[0]) / (fit[-1] - fit[0])
    return np.maximum.accumulate((v_window - v_window.min()) / (v_window.max() - v_window.min()))


def record_noise(t, v, plateau_start_us: float, end_us: float):
    """The trace's noise model from its plateau (`shockcal.velocimetry.record_noise.estimate_noise`); a FeatureError
    when the plateau is too short to estimate it."""
    from shockcal.velocimetry.record_noise import estimate_noise

    try:
        return estimate_noise(t, v, plateau_start_us, end_us)
    except ValueError as exc:
        raise FeatureError(str(exc)) from None


def ends_before(mixture: Mixture, cutoff_us: float) -> np.ndarray:
    """Mask of the components that end (mu + 2 sigma) before the cut-off."""
    return mixture.means + 2 * mixture.sds < cutoff_us


def split_early(mixture: Mixture, cutoff_us: float) -> np.ndarray:
    """Mask of the early (elastic) components: those ending before the cut-off. A single wave puts
    every component on one side; then the latest (resp. earliest) one is moved to the other side."""
    early = ends_before(mixture, cutoff_us)
    if early.all():          # one wave only (elastic, large A): its latest component is the late mixture
        early[np.argmax(mixture.means)] = False
    elif not early.any():    # the precursor merges with the plastic rise: its earliest component is early
        early[np.argmin(mixture.means)] = True
    return early


def feature_times(t_window, cdf_window, mixture: Mixture, early: np.ndarray, cutoff_us: float) -> dict:
    """The five feature times (us) from the mixture split into early and late.

    When no component lies before the cut-off (a precursor too small for EM to give it a component of
    its own: a few m/s ahead of the plastic wave at small A), the stand-in early component is broad,
    and its quantiles are kept inside the elastic part of the window: jump-off not before the window
    starts, elastic plateau not after the cut-off (unclamped, they fell 0.3 us before the arrival and
    on the plastic plateau: v_elastic = v_plastic). The slope times are kept inside the analysis window:
    a single-wave trace's late mixture can be one broad component (a few 1e-5 of the mass, spread over
    the plateau) whose 0.9 quantile lies past the window's end, where the release has arrived (unclamped,
    v_slope2 read 0.001 m/s on two of the study's 1000 104S runs)."""
    early_mix, late_mix = mixture.subset(early), mixture.subset(~early)
    jumpoff, elastic = early_mix.quantile(0.01), early_mix.quantile(0.99)
    if not ends_before(early_mix, cutoff_us).any():
        jumpoff, elastic = max(jumpoff, t_window[0]), min(elastic, cutoff_us)
    end = t_window[-1]        # a single wave's late mixture can be one broad component of a few 1e-5 of the
    slope1 = min(max(late_mix.quantile(0.1), elastic), end)     # mass spread over the plateau: it reaches back
    return {"jumpoff": float(jumpoff), "elastic": float(elastic),   # before the elastic time and past the window
            "slope1": float(slope1), "slope2": float(min(max(late_mix.quantile(0.9), slope1), end)),
            "plastic": float(t_window[np.argmax(cdf_window >= PLASTIC_LEVEL)])}


def slope_half_window_us(half_window_us: float, times: dict) -> float:
    """The slope points' read-out half-window (us): the record's (`half_window_us`, from its noise) or, on a
    steeper plastic rise, `RISE_SHARE` of its rise time (slope point 1 to slope point 2, `times` in us),
    whichever is smaller. A least-squares line through a rise's foot or shoulder is off by about
    0.25 (h / rise time)^2 of the rise (a Gaussian-CDF rise, its 10% and 90% points; 0.6% at the share):
    a 4 ns window on a copper record's 3.3 ns rise read v_slope1 at 3 times its value. The paper's records
    (rises of 110-160 ns, windows of 4-8 ns) keep their window (docs/features.md, "Steep fronts")."""
    return min(half_window_us, RISE_SHARE * (times["slope2"] - times["slope1"]))


def feature_values(t, v, times: dict, half_window_us: float = 0.0, slope_half_window_us: float | None = None) -> dict:
    """The ten feature values: the times (us) and the trace's velocity at each (m/s, `read_velocity`): over
    `half_window_us` (us), the slope points over `slope_half_window_us` (None: the same)."""
    features = {}
    for name in FEATURES:
        window = slope_half_window_us if name.startswith("slope") and slope_half_window_us is not None else half_window_us
        features[f"t_{name}"] = times[name]
        features[f"v_{name}"] = read_velocity(t, v, times[name], window)
    return features


def read_velocity(t, v, time_us: float, half_window_us: float) -> float:
    """The trace's velocity (m/s) at `time_us`: the value at `time_us` of a least-squares line through
    the samples within `half_window_us` of it (a record's noise window), or, when that window holds
    fewer than three samples (a noise-free trace: `half_window_us` 0), the linear interpolation
    between the two samples around it."""
    near = np.abs(t - time_us) <= half_window_us * (1 + 1e-9)
    if near.sum() < 3:
        return float(np.interp(time_us, t, v))
    return float(np.polyfit(t[near] - time_us, v[near], 1)[1])


def fit_mixture(samples: np.ndarray, n_components: int) -> Mixture:
    """The EM fit of highest likelihood over `MIXTURE_STARTS` fixed starts. EM runs on the standardized
    samples, so the tolerance and scikit-learn's variance floor (reg_covar) do not depend on the time unit.
    The reference path (`extract(..., method="pit")`); the extractor uses `fit_mixture_exact`."""
    from sklearn.mixture import GaussianMixture

    centre, spread = samples.mean(), samples.std()
    z = ((samples - centre) / spread)[:, None]
    quantile_means = np.quantile(z, (np.arange(n_components) + 0.5) / n_components)[:, None]
    starts = [dict(means_init=quantile_means, random_state=0)]
    starts += [dict(random_state=k) for k in range(MIXTURE_STARTS - 1)]
    best, best_score = None, -np.inf
    for start in starts:
        gm = GaussianMixture(n_components, tol=MIXTURE_TOL, max_iter=MIXTURE_MAX_ITER, **start).fit(z)
        score = gm.score(z)
        if score > best_score:
            best, best_score = gm, score
    return Mixture(best.weights_, centre + spread * best.means_.ravel(), spread * np.sqrt(best.covariances_.ravel()))


def fit_mixture_exact(t_window: np.ndarray, cdf_window: np.ndarray, samples: np.ndarray, n_components: int) -> Mixture:
    """The EM fit of highest expected log-likelihood under the piecewise-linear CDF the PIT samples are
    drawn from (`shockcal.velocimetry.mixture_fit`): the limit of `fit_mixture` as the number of samples grows. The
    same starts (scikit-learn's, made from the samples), the same EM steps and stopping rule
    (`MIXTURE_TOL`), the same variance floor, on the standardized scale."""
    from shockcal.velocimetry.mixture_fit import fit_piecewise_linear_cdf

    (weights, means, sds), _ = fit_piecewise_linear_cdf(t_window, cdf_window, n_components, MIXTURE_STARTS,
                                                        MIXTURE_TOL, MIXTURE_MAX_ITER, starts=samples)
    return Mixture(weights, means, sds)


def readout_replicates(t, v, settings: ExtractorSettings, replicates: int, seed: int, robust: bool | None = None
                       ) -> pd.DataFrame:
    """The features of `replicates` copies of a noisy trace's signal, each with an independent replicate
    of its noise added: a parametric bootstrap. The signal is the trace smoothed by the read-out's own
    local line (scipy's Savitzky-Golay filter of order 1 over the slope points' read-out window, which
    is the record's unless its plastic rise is steep: `slope_half_window_us`), the noise the AR
    model fitted to the trace's plateau residuals (`shockcal.velocimetry.record_noise`). Their spread is the
    extractor's read-out error on the trace.

    Args:
        t, v: the trace (us, m/s); it must be noisy (`is_noisy`: a simulation has no noise to replicate).
        settings: the shot's `ExtractorSettings`.
        replicates: how many noise replicates.
        seed: seeds the replicates (`numpy.random.default_rng`).
        robust: passed to `extract` for the replicates (None: robust, as for the trace itself).

    Returns:
        One row per replicate that has features, the ten feature columns (a replicate without features
        is left out).
    """
    import pandas as pd

    t, v = np.asarray(t, dtype=float), np.asarray(v, dtype=float)
    extraction = extract(t, v, settings)
    noise = extraction.noise
    if noise is None:
        raise FeatureError("the trace is noise-free before its arrival (a simulation): it has no noise to replicate")
    half_width = max(int(round(extraction.slope_half_window_us / np.median(np.diff(t)))), 1)
    signal = savgol_filter(v, 2 * half_width + 1, 1)
    rng = np.random.default_rng(seed)
    rows = []
    for _ in range(replicates):
        try:
            rows.append(extract(t, signal + noise.simulate(len(v), rng), settings, robust=robust).features)
        except FeatureError:
            continue
    return pd.DataFrame(rows, columns=COLUMNS)


def extract_features(t, v, settings: ExtractorSettings = DEFAULT_SETTINGS) -> dict:
    """The ten feature values of a trace (t in us, v in m/s)."""
    return extract(t, v, settings).features
