"""Bayesian calibration of the strength inputs from measured features (SPEC sections 5-6).

For the shots calibrated together, the measured features y (m/s, four per shot) are modelled as

    y = eta(theta) + e + eps,   e ~ t_nu(0, s C_eta(theta)),   eps ~ N(0, Sigma_y / lambda_y),

eta and C_eta the emulator's predictive mean and covariance, (nu, s) its error model (a Student t
fitted to its K-fold errors, `shockcal.error_model`; nu = inf, s = 1 is the paper's Gaussian), one
e per emulator block (their errors are independent), Sigma_y diagonal with sd =
`observed.sd_fraction` (1%) of each measured feature, lambda_y ~ Gamma(5, 5), theta uniform on the
prior box. The emulator's hyperparameters are fixed at their fitted mode (modular Bayes; see
docs/calibration.md). A point is (theta in native units, lambda_y); both priors are reached from the
unit cube (`Problem.prior_transform`).

Sampling (`shockcal.sampler`): importance nested sampling (nautilus) from the unit cube through
`Problem.prior_transform`, with the batch log-likelihood `Problem.log_likelihood`.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace

import numpy as np
import pandas as pd
from scipy import stats

from shockcal.emulator import CALIBRATION_FEATURES
from shockcal.error_model import ErrorModel
from shockcal.errors import InputError, ShockcalError
from shockcal.plausibility import check_observed_table
from shockcal.progress import progress
from shockcal.sampler import WeightedDraws, nested_sample
from shockcal.seeds import stream_seed

log = logging.getLogger("shockcal.calibration")
LAMBDA_Y_PRIOR = (5.0, 5.0)   # Gamma(shape, rate) of the observation-precision scale


@dataclass
class Problem:
    """Everything the posterior density needs: a predictive model, observed features, prior box.

    `predict` maps theta (N, d) in native units to the predictive mean (N, F) and covariance
    (N, F, F) of the features, m/s: any emulator (`PCGPEmulator.predict` from a notebook, or a
    study's `Emulator` through `Problem.build`). Points are (theta, lambda_y). `prior_transform`
    and `log_likelihood` are the pair a nested or SMC sampler takes (vectorised over a batch of
    points); `log_posterior` is the same density for MCMC in (theta, log lambda_y).
    `error_groups`: (feature columns, ErrorModel) pairs covering the features once; default, one
    Gaussian over all of them.
    """

    predict: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]
    observed: np.ndarray      # (F,) m/s
    obs_sd: np.ndarray        # (F,) m/s
    names: list[str]          # calibrated inputs, native units
    lower: np.ndarray
    upper: np.ndarray
    label: str = "calibration"
    error_groups: list[tuple[np.ndarray, ErrorModel]] | None = None

    @classmethod
    def build(cls, emulator, shots, observed_table: pd.DataFrame, sd_fraction: float, source: str = "observed"):
        """The study's problem: the inputs `shots` need, their box, and their measured features."""
        names = emulator.required_inputs(shots)
        lower, upper = emulator.input_bounds(names)
        y = observed_vector(observed_table, shots, emulator.feature_names, source)

        def predict(theta):
            return emulator.predict(dict(zip(names, theta.T)), list(shots))

        return cls(predict, y, sd_fraction * np.abs(y), names, np.asarray(lower), np.asarray(upper), "+".join(shots),
                   emulator.error_groups(shots))

    @property
    def ndim(self) -> int:
        return len(self.names) + 1

    def prior_transform(self, u: np.ndarray) -> np.ndarray:
        """Unit cube (N, d + 1) -> (theta uniform on the box, lambda_y ~ Gamma(5, 5))."""
        u = np.atleast_2d(u)
        shape, rate = LAMBDA_Y_PRIOR
        theta = self.lower + u[:, :-1] * (self.upper - self.lower)
        return np.column_stack([theta, stats.gamma.ppf(u[:, -1], shape, scale=1.0 / rate)])

    def cube_power(self, powers: Mapping[str, float], others: str = "error") -> np.ndarray:
        """`nested_sample`'s per-coordinate unit-cube power from powers of named inputs (1 for the
        others and lambda_y). A name this problem does not calibrate is an error, or with
        `others="ignore"` skipped (a study's powers in a single-shot calibration: 104S has no Delta2)."""
        unknown = sorted(set(powers) - set(self.names))
        if unknown and others != "ignore":
            raise InputError(f"{self.label}: calibration.cube_power names {unknown}, not among the calibrated "
                             f"inputs {self.names}")
        return np.array([float(powers.get(name, 1.0)) for name in self.names] + [1.0])

    def log_likelihood(self, points: np.ndarray) -> np.ndarray:
        """Log-likelihood of the observed features at points (N, d + 1) = (theta, lambda_y)
        inside the box, normalising constants included (so the evidence is a true marginal likelihood).
        A non-finite value is an error naming the point: it means the emulator is broken there."""
        points = np.atleast_2d(points)
        theta, lam = points[:, :-1], points[:, -1]
        mean, cov = self.predict(theta)
        resid = self.observed - mean
        groups = self.error_groups or [(np.arange(len(self.observed)), ErrorModel())]
        value = np.zeros(len(points))
        for cols, error in groups:
            noise_var = self.obs_sd[cols] ** 2 / lam[:, None]
            value += error.log_density(resid[:, cols], cov[:, cols[:, None], cols[None, :]], noise_var)
        bad = ~np.isfinite(value)
        if bad.any():
            point = dict(zip([*self.names, "lambda_y"], points[np.argmax(bad)].tolist()))
            raise InputError(f"{self.label}: the log-likelihood is not finite at {point} "
                             "(the emulator's prediction or covariance is invalid there)")
        return value

    def log_posterior(self, x: np.ndarray) -> np.ndarray:
        """Log posterior (up to a constant) at x (N, d + 1) = (theta, log lambda_y); -inf outside the
        box. The Gamma prior of lambda_y and the Jacobian of the log are included."""
        x = np.atleast_2d(x)
        out = np.full(len(x), -np.inf)
        inside = np.all((x[:, :-1] >= self.lower) & (x[:, :-1] <= self.upper), axis=1) & np.isfinite(x[:, -1])
        if inside.any():
            log_lam = x[inside, -1]
            lam = np.exp(log_lam)
            shape, rate = LAMBDA_Y_PRIOR
            out[inside] = self.log_likelihood(np.column_stack([x[inside, :-1], lam])) + shape * log_lam - rate * lam
        return out


def observed_vector(table: pd.DataFrame, shots, feature_names, source: str) -> np.ndarray:
    """The measured features of `shots`, shot-major; missing or non-positive values are errors."""
    from shockcal.io import require_columns

    require_columns(table, ["shot", *feature_names], source)
    values = []
    for shot in shots:
        rows = table[table["shot"].astype(str) == shot]
        if rows.empty:
            raise InputError(f"{source}: no observed features for shot {shot} (have {sorted(table['shot'].astype(str))})")
        row = rows.iloc[0][feature_names].to_numpy(dtype=float)
        bad = [f for f, v in zip(feature_names, row) if not np.isfinite(v) or v <= 0]
        if bad:
            raise InputError(f"{source}: shot {shot}: observed feature(s) {bad} missing or not positive")
        values.append(row)
    return np.concatenate(values)


@dataclass(frozen=True)
class SamplerSettings:
    """nautilus: live points, the effective sample size (Kish) to reach, the number of equal-weight
    draws written, the seed, the unit-cube power of named inputs (`nested_sample`'s `cube_power`:
    where the sampler looks, not the posterior) and the likelihood evaluations after which a run that
    has not reached `n_eff` stops with an error."""

    n_live: int = 1000
    n_eff: int = 3000
    draws: int = 10000
    seed: int = 0
    cube_power: Mapping[str, float] = field(default_factory=dict)
    max_evaluations: int = 500_000


@dataclass(frozen=True)
class CalibrationSettings:
    """What a calibration needs besides the emulator and the measured features: the sampler, the
    observation sd as a fraction of each measured feature, whether to check that the measurements
    look like m/s and us (`shockcal.plausibility`), and each parameter's unit for the summary."""

    sampler: SamplerSettings = SamplerSettings()
    sd_fraction: float = 0.01
    check_units: bool = True
    units: Mapping[str, str] = field(default_factory=dict)

    @classmethod
    def from_config(cls, config: dict, shots, check: bool = False) -> CalibrationSettings:
        """The adapter from a validated config: `calibration` (with `check`, the synthetic-truth
        trials' `calibration.check`, whose draws are its n_eff; `calibration.cube_power` for both),
        seeded by the shots' "calibration" stream of study.seed (a trial reseeds from its own stream)."""
        section = config["calibration"]["check"] if check else config["calibration"]
        draws = section["n_eff"] if check else section["draws"]
        seed = stream_seed(config["study"]["seed"], "calibration", *shots)
        sampler = SamplerSettings(section["n_live"], section["n_eff"], draws, seed, config["calibration"]["cube_power"],
                                  config["calibration"]["max_evaluations"])
        return cls(sampler, config["observed"]["sd_fraction"], config["checks"]["observed_units"],
                   {name: box["unit"] for name, box in config["inputs"].items()})

    def with_sampler(self, **changes) -> CalibrationSettings:
        """These settings with some sampler settings changed (e.g. `seed`, `n_eff`)."""
        return replace(self, sampler=replace(self.sampler, **changes))


def sample(problem: Problem, settings: SamplerSettings, other_powers: str = "error"
           ) -> tuple[pd.DataFrame, pd.DataFrame, dict]:
    """Sample the posterior: equal-weight draws (theta, lambda_y, log_likelihood) resampled from the
    weighted ones, the summary of the weighted draws, and run info (evidence, likelihood
    evaluations, Kish ESS, distinct draws). `other_powers`: `Problem.cube_power`'s `others`."""
    power = problem.cube_power(settings.cube_power, other_powers)
    weighted = nested_sample(problem.prior_transform, problem.log_likelihood, problem.ndim, settings.n_live,
                             settings.n_eff, settings.seed, power, settings.max_evaluations)
    rows = weighted.resample(settings.draws, np.random.default_rng(settings.seed))
    frame = pd.DataFrame(weighted.points[rows], columns=[*problem.names, "lambda_y"])
    frame["log_likelihood"] = weighted.log_likelihood[rows]
    info = {"sampler": "nautilus", "n_live": settings.n_live, "n_eff_target": settings.n_eff, "seed": settings.seed,
            "log_evidence": weighted.log_evidence, "likelihood_evaluations": weighted.n_likelihood,
            "cube_power": {k: float(p) for k, p in zip(problem.names, power) if p != 1.0},
            "weighted_draws": len(weighted.points), "ess_kish": weighted.kish_ess(), "retained": len(frame),
            "distinct_draws": int(len(np.unique(rows)))}
    return frame, summarize(weighted, [*problem.names, "lambda_y"]), info


SUMMARY_QUANTILES = (0.05, 0.5, 0.95)


def summarize(draws: WeightedDraws, names: list[str]) -> pd.DataFrame:
    """Per parameter: weighted mean, sd, 5/50/95% quantiles with their Monte Carlo standard errors
    (`quantile_mcse`), and the Kish ESS of the weights."""
    w, ess = draws.weights, draws.kish_ess()
    rows = []
    for j, name in enumerate(names):
        x = draws.points[:, j]
        mean = float(np.sum(w * x))
        row = {"parameter": name, "mean": mean, "sd": float(np.sqrt(np.sum(w * (x - mean) ** 2)))}
        for p, q, mcse in zip(SUMMARY_QUANTILES, weighted_quantiles(x, w, SUMMARY_QUANTILES),
                              quantile_mcse(x, w, SUMMARY_QUANTILES)):
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


def weighted_quantiles(x: np.ndarray, w: np.ndarray, q) -> np.ndarray:
    """Quantiles of weighted draws: the inverse of the midpoint-interpolated weighted CDF."""
    order = np.argsort(x)
    cdf = np.cumsum(w[order]) - 0.5 * w[order]
    return np.interp(q, cdf / w.sum(), x[order])


def calibrate(emulator, shots, observed: pd.DataFrame, settings: CalibrationSettings, source: str = "observed"
              ) -> tuple[pd.DataFrame, pd.DataFrame, dict]:
    """Calibrate `shots` jointly (one shot = single-shot calibration) on the measured features in
    `observed` (one row per shot, m/s and us; `source` names it in errors): samples, summary, run info."""
    problem = Problem.build(emulator, shots, observed, settings.sd_fraction, source)
    check_observed_table(observed, shots, source, settings.check_units)
    samples, summary, info = sample(problem, settings.sampler, other_powers="ignore")
    units = {**{k: settings.units.get(k, "-") for k in problem.names}, "lambda_y": "-"}
    summary.insert(1, "unit", summary["parameter"].map(units))
    info.update(shots=list(shots), parameters=problem.names, units=units,
                observed=problem.observed.tolist(), observed_sd_m_s=problem.obs_sd.tolist())
    return samples, summary, info


def synthetic_truth(emulator, shots, settings: CalibrationSettings, trials, seed: int, truths=None) -> pd.DataFrame:
    """Calibrate on synthetic truth with a known theta; one row per trial and parameter.

    `trials` is a count or the trial numbers to run (a range): each trial draws from its own random
    stream (child `trial` of `seed`), so a check split into batches of trials (the workflow's jobs)
    gives the same rows as one run. A trial draws lambda_y from its prior and takes theta and
    noise-free features either from the emulator (theta uniform on the box, features from its
    predictive distribution at theta) or, when `truths` is given, from hydrocode run number `trial`
    among the usable ones (`HydroTruths`). Observation noise of sd = sd_fraction / sqrt(lambda_y) of
    each feature is added and the features are calibrated with `settings` (the sampler reseeded from
    the trial's stream). Columns:
    trial, parameter, truth, q05, q95, inside (the 90% interval holds the truth), ess (Kish ESS),
    truth_hpd_mass (the trial's `hpd_mass` of the truth, the same on each of its rows), status ("ok" or
    "failed") and reason. A trial that fails (the sampler at `max_evaluations`, no positive noise draw)
    is recorded with its reason and empty results, and the next one runs; the coverage leaves it out
    (`usable_trials`) and counts it.
    """
    trial_ids = range(trials) if isinstance(trials, int) else trials
    names = emulator.required_inputs(shots)
    hydro_draws = None if truths is None else truths.table(names, shots)
    if hydro_draws is not None and max(trial_ids, default=-1) >= len(hydro_draws):
        raise InputError(f"synthetic truth: trial {max(trial_ids)} needs hydrocode run number {max(trial_ids) + 1}, "
                         f"but only {len(hydro_draws)} truth runs are usable")
    rows = []
    batch = progress(trial_ids, len(trial_ids), f"synthetic trials {'+'.join(shots)}", "trial", log)
    for done, trial in enumerate(batch, 1):
        rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(trial,)))
        try:
            rows += _trial_rows(emulator, shots, names, settings, trial, rng, hydro_draws)
        except ShockcalError as error:     # recorded and left out of the coverage, never the end of the batch
            log.warning("synthetic trial %d failed: %s", trial, error)
            rows += [{"trial": trial, "parameter": name, "status": "failed", "reason": str(error)}
                     for name in [*names, "lambda_y"]]
        log.debug("synthetic trial %d done (%d of %d)", trial, done, len(trial_ids))   # progress: count, time left
    table = pd.DataFrame(rows, columns=CHECK_COLUMNS)
    table["inside"] = table["inside"].astype("boolean")
    return table


CHECK_COLUMNS = ["trial", "parameter", "truth", "q05", "q95", "inside", "ess", "truth_hpd_mass", "status", "reason"]


def _trial_rows(emulator, shots, names, settings: CalibrationSettings, trial, rng, hydro_draws) -> list[dict]:
    """One synthetic-truth trial: its truth, pseudo-measurement and calibration; a row per parameter."""
    if hydro_draws is None:
        theta, eta = _emulator_truth(emulator, shots, names, rng)
    else:
        theta, eta = hydro_draws[trial]
    lam, y = _noisy_features(eta, settings.sd_fraction, rng, trial)
    observed = pd.DataFrame(y.reshape(len(shots), -1), columns=emulator.feature_names).assign(shot=list(shots))
    trial_settings = settings.with_sampler(seed=int(rng.integers(2**31)))
    draws, summary, _ = calibrate(emulator, shots, observed, trial_settings, source=f"synthetic trial {trial}")
    summary = summary.set_index("parameter")
    problem = Problem.build(emulator, shots, observed, settings.sd_fraction)
    truth_ll = problem.log_likelihood(np.append(theta, lam)[None])[0]
    mass = hpd_mass(log_density(draws["log_likelihood"], draws["lambda_y"]), log_density(truth_ll, lam))
    rows = []
    for name, truth in [*zip(names, theta), ("lambda_y", lam)]:
        q05, q95 = summary.loc[name, ["q05", "q95"]]
        rows.append({"trial": trial, "parameter": name, "truth": truth, "q05": q05, "q95": q95,
                     "inside": bool(q05 <= truth <= q95), "ess": summary.loc[name, "ess"],
                     "truth_hpd_mass": mass, "status": "ok", "reason": ""})
    return rows


def log_density(log_likelihood, lambda_y):
    """Log posterior density of (theta, lambda_y) up to a constant: the log-likelihood plus lambda_y's
    Gamma prior (theta's prior is uniform on the box)."""
    shape, rate = LAMBDA_Y_PRIOR
    return np.asarray(log_likelihood) + stats.gamma.logpdf(lambda_y, shape, scale=1.0 / rate)


def hpd_mass(draw_log_density, truth_log_density: float) -> float:
    """Share of equal-weight posterior draws denser than the truth: the mass of the smallest credible
    region that holds it. Uniform on [0, 1] when the truths come from the prior and the posterior is
    right, whatever its shape; unlike the per-parameter intervals, one joint number per trial."""
    return float(np.mean(np.asarray(draw_log_density) > truth_log_density))


def _noisy_features(eta, sd_fraction, rng, trial, attempts: int = 100):
    """(lambda_y, pseudo-measured features): lambda_y from its prior and noise of sd = sd_fraction /
    sqrt(lambda_y) of each feature. No measurement reports a non-positive feature: such a draw is
    drawn again (the features are conditioned on being positive)."""
    for _ in range(attempts):
        lam = rng.gamma(LAMBDA_Y_PRIOR[0], 1.0 / LAMBDA_Y_PRIOR[1])
        y = eta + sd_fraction * np.abs(eta) / np.sqrt(lam) * rng.normal(size=eta.shape)
        if np.all(y > 0):
            return lam, y
    raise InputError(f"synthetic trial {trial}: {attempts} noise draws all gave a non-positive feature "
                     f"(noise-free features {np.round(eta, 3).tolist()})")


def _emulator_truth(emulator, shots, names, rng):
    """(theta, features): theta uniform on the box, features from the emulator's predictive
    distribution at theta (its error model's, block by block)."""
    lower, upper = emulator.input_bounds(names)
    theta = rng.uniform(lower, upper)
    mean, cov = emulator.predict({k: np.array([v]) for k, v in zip(names, theta)}, shots)
    features = np.empty(mean.shape[1])
    for cols, error in emulator.error_groups(shots):
        features[cols] = error.sample(mean[0, cols], cov[0, cols[:, None], cols[None, :]], rng)
    return theta, features


@dataclass
class HydroTruths:
    """Hydrocode runs as synthetic truth: their design (theta per run) and, per shot, their features."""

    design: pd.DataFrame
    features: dict            # shot -> features table (run, status, feature columns)

    @classmethod
    def read(cls, design_path, feature_paths: dict, shots) -> HydroTruths:
        """From a design table and each shot's features table (CSV or Parquet); every shot calibrated
        needs its features."""
        from shockcal.io import read_table

        missing = sorted(set(shots) - set(feature_paths))
        if missing:
            raise InputError(f"calibrate-check: no --truth-features for shot(s) {missing}")
        return cls(read_table(design_path), {shot: read_table(path) for shot, path in feature_paths.items()})

    def table(self, names, shots) -> list:
        """(theta, features) of each usable run (every shot's features ok and positive), in run order."""
        table = self.design.set_index("run")
        for shot in shots:
            ok = self.features[shot].query("status == 'ok'").set_index("run")
            table = table.join(ok[CALIBRATION_FEATURES].add_prefix(f"{shot}:"), how="inner")
        columns = [f"{shot}:{f}" for shot in shots for f in CALIBRATION_FEATURES]
        usable = table[(table[columns] > 0).all(axis=1)].sort_index()
        log.info("hydrocode truth: %d of %d runs usable (every shot ok, features positive)", len(usable), len(self.design))
        return list(zip(usable[names].to_numpy(float), usable[columns].to_numpy(float)))


def usable_trials(trials: pd.DataFrame) -> pd.DataFrame:
    """The rows of trials that finished: status "ok", or no status (rows from before the status
    column, 2026-11-25, are all of finished trials)."""
    return trials if "status" not in trials else trials[trials["status"].fillna("ok") == "ok"]


def coverage_table(trials: pd.DataFrame) -> pd.DataFrame:
    """Per parameter, over the trials that finished (`usable_trials`; failed_trials counts the others):
    trials, share of 90% intervals holding the truth (nominal 0.90), the central 95% binomial band of
    that share for a calibrated method (band_low, band_high), whether it lies in the band, the shares
    of truths below q05 and above q95 (nominal 0.05 each: a lopsided miss points to a shifted
    posterior, an even one to a narrow one), and the smallest Kish ESS of any trial."""
    usable = usable_trials(trials).astype({"inside": bool})
    usable = usable.assign(below_q05=usable["truth"] < usable["q05"], above_q95=usable["truth"] > usable["q95"])
    if usable.empty:
        reasons = trials.groupby("trial")["reason"].first() if "reason" in trials else pd.Series(dtype=str)
        raise InputError(f"no synthetic-truth trial finished: {len(reasons)} failed"
                         + (f", the first with: {reasons.iloc[0]}" if len(reasons) else ""))
    table = usable.groupby("parameter", sort=False).agg(
        trials=("trial", "nunique"), coverage90=("inside", "mean"), below_q05=("below_q05", "mean"),
        above_q95=("above_q95", "mean"), min_ess=("ess", "min")).reset_index()
    failed = trials.groupby("parameter", sort=False)["trial"].nunique() - usable.groupby("parameter")["trial"].nunique()
    table["failed_trials"] = table["parameter"].map(failed).fillna(0).astype(int)
    table["band_low"], table["band_high"] = binomial_band(table["trials"])
    table["within_band"] = table["coverage90"].between(table["band_low"], table["band_high"])
    return table


def joint_coverage(trials: pd.DataFrame) -> dict:
    """The joint check from the trials' `truth_hpd_mass`: the share of trials whose truth lies in the
    90% highest-density region, its central 95% binomial band, and the Kolmogorov-Smirnov p-value of
    the masses against the uniform distribution they follow for a calibrated method."""
    mass = usable_trials(trials).groupby("trial")["truth_hpd_mass"].first().to_numpy()
    band_low, band_high = binomial_band(len(mass))
    return {"trials": len(mass), "coverage90": float(np.mean(mass <= 0.9)), "band_low": band_low,
            "band_high": band_high, "uniform_ks_p": float(stats.kstest(mass, "uniform").pvalue)}


def binomial_band(trials):
    """The central 95% band of the share of `trials` (a count or an array of counts) that a
    calibrated 90% interval covers."""
    return stats.binom.ppf(0.025, trials, 0.9) / trials, stats.binom.ppf(0.975, trials, 0.9) / trials
