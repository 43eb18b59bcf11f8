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
3. The windowed trace is standardized to run from 0 to 1, made monotone (running maximum) and read
   as a CDF; 10,000 samples are drawn by the probability integral transform: stratified uniform
   draws u_i = (i + 1/2)/N (no random numbers) mapped through the inverse CDF, linear interpolation
   of (y, t). The samples move smoothly with the trace, so neighbouring runs get neighbouring samples.
   Their distribution is known exactly: uniform between consecutive (t, y) pairs where y rises.
4. A k = 5 Gaussian mixture is fitted by EM to that exact distribution, the limit of infinitely many
   samples (`fit_mixture_exact`, `shockcal.mixture_fit`: Gauss-Legendre quadrature over its uniform
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
   trace reaches 0.995. Each velocity is the trace's value at that time.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from scipy import optimize, stats

from shockcal.errors import InputError, ShockcalError

if TYPE_CHECKING:
    import pandas as pd

log = logging.getLogger("shockcal.features")
FEATURES = ("jumpoff", "elastic", "plastic", "slope1", "slope2")
COLUMNS = [f"{axis}_{name}" for name in FEATURES for axis in ("t", "v")]
CALIBRATION_FEATURES = ["v_elastic", "v_plastic", "v_slope1", "v_slope2"]   # what the emulator and calibration use
ARRIVAL_FRACTION = 0.02
QUIET_ARRIVAL_FRACTION = 0.002
NOISE_MULTIPLE = 5.0
PRE_ARRIVAL_US = 0.05
PLASTIC_LEVEL = 0.995
MIXTURE_STARTS = 3         # EM starts: quantile-spaced means, then k-means seeded 0, 1, ...
MIXTURE_TOL = 1e-5         # EM stops when the mean log-likelihood gains less than this
MIXTURE_MAX_ITER = 1000


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


@dataclass(frozen=True)
class ExtractorSettings:
    """How one shot's traces are read; the defaults are the config schema's (a test keeps them equal).

    Args:
        window_after_arrival_us: end of the analysis window after the detected arrival (us; config
            `shots.<shot>.analysis`); it must end before the release from the flyer's back arrives.
        cutoff_after_arrival_us: the elastic cut-off after the arrival (us): components ending before
            it form the early (elastic) mixture.
        n_components: Gaussian mixture components (config `features`).
        n_samples: stratified PIT samples of the trace's CDF (config `features`).
    """

    window_after_arrival_us: float = 1.2
    cutoff_after_arrival_us: float = 0.04
    n_components: int = 5
    n_samples: int = 10000


def extract(t, v, settings: ExtractorSettings = ExtractorSettings(), method: str = "exact") -> Extraction:
    """Run the extractor on one trace; raises FeatureError when it cannot.

    Args:
        t: times (us), increasing.
        v: free-surface velocity (m/s) at those times.
        settings: the analysis window, elastic cut-off and mixture size (`ExtractorSettings`).
        method: "exact" fits the mixture to the standardized trace's exact CDF (`fit_mixture_exact`,
            from starts made from the n_samples PIT samples); "pit" (the reference, 30-90 times slower)
            fits it by scikit-learn's EM to the samples (`fit_mixture`). Both draw the samples: the
            figures show them.

    Returns:
        An `Extraction`: the ten features (times us, velocities m/s) and the intermediate steps.
    """
    t, v = np.asarray(t, dtype=float), np.asarray(v, dtype=float)
    bad = ~(np.isfinite(t) & np.isfinite(v))
    if bad.any():
        raise FeatureError(f"{int(bad.sum())} non-finite values in the trace (first at index {int(np.argmax(bad))})")
    arrival = detect_arrival(t, v)
    start, end = arrival - PRE_ARRIVAL_US, arrival + settings.window_after_arrival_us
    if end > t[-1]:
        raise FeatureError(f"trace ends at {t[-1]:.3f} us, before the analysis window ({end:.3f} us)")
    inside = (t >= start) & (t <= end)
    tw, vw = t[inside], v[inside]
    y = np.maximum.accumulate((vw - vw.min()) / (vw.max() - vw.min()))
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
    features = feature_values(t, v, tw, y, mixture, early, cutoff)
    return Extraction(features, arrival, cutoff, (start, end), tw, y, samples, mixture, early)


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


def feature_values(t, v, t_window, cdf_window, mixture: Mixture, early: np.ndarray, cutoff_us: float) -> dict:
    """The ten feature values (times us, velocities m/s) from the mixture split into early and late.

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
    times = {"jumpoff": jumpoff, "elastic": elastic,                # before the elastic time and past the window
             "slope1": slope1, "slope2": min(max(late_mix.quantile(0.9), slope1), end),
             "plastic": float(t_window[np.argmax(cdf_window >= PLASTIC_LEVEL)])}
    features = {}
    for name in FEATURES:
        features[f"t_{name}"] = float(times[name])
        features[f"v_{name}"] = float(np.interp(times[name], t, v))
    return features


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
    drawn from (`shockcal.mixture_fit`): the limit of `fit_mixture` as the number of samples grows. The
    same starts (scikit-learn's, made from the samples), the same EM steps and stopping rule
    (`MIXTURE_TOL`), the same variance floor, on the standardized scale."""
    from shockcal.mixture_fit import fit_piecewise_linear_cdf

    (weights, means, sds), _ = fit_piecewise_linear_cdf(t_window, cdf_window, n_components, MIXTURE_STARTS,
                                                        MIXTURE_TOL, MIXTURE_MAX_ITER, starts=samples)
    return Mixture(weights, means, sds)


def extract_features(t, v, settings: ExtractorSettings = ExtractorSettings()) -> dict:
    """The ten feature values of a trace (t in us, v in m/s)."""
    return extract(t, v, settings).features


def features_table(traces, settings: ExtractorSettings, source: str = "simulations") -> pd.DataFrame:
    """One row per simulated run (a simulations table: run, status, reason, t_us, v_m_s): run, status,
    reason and the ten features.

    Failed simulations keep their status and reason; a trace the extractor cannot read becomes
    status "failed" with the extractor's reason. A table that is not a simulations table (columns
    missing, no rows, run ids that are not whole numbers, traces that are not lists of numbers: a CSV
    copy of a chunk) is an InputError naming `source` and the run.
    """
    import pandas as pd

    from shockcal.io import integer_ids, require_columns

    require_columns(traces, ["run", "status", "reason", "t_us", "v_m_s"], source)
    if traces.empty:
        raise InputError(f"{source}: no runs (a simulations table with no rows)")
    traces = integer_ids(traces, "run", source)
    rows = []
    for record in traces.to_dict("records"):
        row = {"run": int(record["run"]), "status": record["status"], "reason": record["reason"]}
        if record["status"] == "ok":
            t, v = (_trace_column(record, column, source) for column in ("t_us", "v_m_s"))
            try:
                row.update(extract_features(t, v, settings))
            except FeatureError as exc:
                row.update(status="failed", reason=f"feature extraction: {exc}")
        rows.append(row)
    table = pd.DataFrame(rows)
    for column in COLUMNS:
        table[column] = table[column].astype(float) if column in table else np.nan
    return table[["run", "status", "reason", *COLUMNS]].sort_values("run").reset_index(drop=True)


def _trace_column(record: dict, column: str, source) -> np.ndarray:
    """A run's trace column (`t_us` or `v_m_s`) as floats; text (a chunk saved as CSV) or a trace of
    another length than its partner is an InputError naming the run."""
    value = record[column]
    if isinstance(value, str) or np.ndim(value) != 1:
        raise InputError(f"{source}: run {record['run']}: {column} is {type(value).__name__}, not a list of numbers "
                         "(simulation tables are Parquet, as `shockcal simulate` writes them)")
    try:
        values = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{source}: run {record['run']}: {column} holds values that are not numbers") from None
    if len(values) != len(np.asarray(record["t_us"] if column == "v_m_s" else record["v_m_s"])):
        raise InputError(f"{source}: run {record['run']}: t_us and v_m_s differ in length")
    return values


def record_features(path, settings: ExtractorSettings, shot: str, time_column=None, velocity_column=None) -> dict:
    """The ten features of a measured record (`shockcal.records.read_record`) of `shot`; an InputError
    naming the record and the shot when it has none."""
    from shockcal.records import read_record

    t, v = read_record(path, _column(time_column), _column(velocity_column))
    try:
        return extract_features(t, v, settings)
    except FeatureError as exc:
        raise InputError(f"record {path}: no features for shot {shot}: {exc}") from exc


def _column(value):
    return int(value) if isinstance(value, str) and value.isdigit() else value


def check_failures(table, max_fraction: float, shot: str) -> None:
    """Log the excluded count; stop when more than `max_fraction` of the runs failed, or when there are
    no runs (or no `status` column: not a features table)."""
    from shockcal.io import require_columns

    require_columns(table, ["run", "status", "reason"], f"features of shot {shot}")
    if table.empty:
        raise InputError(f"features of shot {shot}: no runs (a features table with no rows)")
    failed = table[table["status"] != "ok"]
    if failed.empty:
        log.info("shot %s: all %d runs have features", shot, len(table))
        return
    log.warning("shot %s: %d of %d runs failed and are excluded downstream", shot, len(failed), len(table))
    if len(failed) > max_fraction * len(table):
        worst = "\n".join(f"  run {r.run}: {r.reason}" for r in failed.head(10).itertuples())
        raise ShockcalError(f"shot {shot}: {len(failed)} of {len(table)} runs failed, more than the allowed "
                            f"{max_fraction:.0%} (simulate.max_failed_fraction); the first:\n{worst}")
