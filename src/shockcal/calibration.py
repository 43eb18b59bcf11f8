"""Bayesian calibration of the strength inputs from measured features (SPEC sections 5-6).

For the shots calibrated together, the measured features y (m/s, four per shot) are modelled as

    y ~ N( eta(theta), C_eta(theta) + Sigma_y / lambda_y ),

eta and C_eta the emulator's predictive mean and covariance, Sigma_y diagonal with sd =
`observed.sd_fraction` (1%) of each measured feature, lambda_y ~ Gamma(5, 5), theta uniform on the
prior box. The emulator's hyperparameters are fixed at their fitted mode (modular Bayes; see
docs/calibration.md). The sampled vector is (theta in native units, log lambda_y); the density
includes the Jacobian of the log.

Sampling (`shockcal.sampler`): an ensemble whose walkers start spread over the whole prior box,
with mode-hopping moves, so every mode is populated from the start.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np
import pandas as pd

from shockcal.diagnostics import RHAT_LIMIT, ess_bulk, ess_tail, split_rhat
from shockcal.emulator import CALIBRATION_FEATURES
from shockcal.errors import InputError
from shockcal.plausibility import check_observed_table
from shockcal.sampler import run_ensemble

log = logging.getLogger("shockcal.calibration")
LAMBDA_Y_PRIOR = (5.0, 5.0)   # Gamma(shape, rate) of the observation-precision scale


@dataclass
class Problem:
    """Everything the posterior density needs: emulator, shots, observed features, prior box."""

    emulator: object
    shots: list[str]
    observed: np.ndarray      # (F,) m/s, shot-major, emulator.feature_names order
    obs_sd: np.ndarray        # (F,) m/s
    names: list[str]          # calibrated design inputs, native units
    lower: np.ndarray
    upper: np.ndarray

    @classmethod
    def build(cls, emulator, shots, observed_table: pd.DataFrame, sd_fraction: float, source: str = "observed"):
        names = emulator.required_inputs(shots)
        lower, upper = emulator.input_bounds(names)
        y = observed_vector(observed_table, shots, emulator.feature_names, source)
        return cls(emulator, list(shots), y, sd_fraction * np.abs(y), names, lower, upper)

    @property
    def ndim(self) -> int:
        return len(self.names) + 1

    def log_posterior(self, x: np.ndarray) -> np.ndarray:
        """Log posterior (up to a constant) of walkers x (N, d + 1) = (theta, log lambda_y)."""
        x = np.atleast_2d(x)
        theta, log_lam = x[:, :-1], x[:, -1]
        out = np.full(len(x), -np.inf)
        inside = np.all((theta >= self.lower) & (theta <= self.upper), axis=1) & np.isfinite(log_lam)
        if not inside.any():
            return out
        lam = np.exp(log_lam[inside])
        mean, cov = self.emulator.predict(dict(zip(self.names, theta[inside].T)), self.shots)
        cov = cov + (self.obs_sd**2)[None, :] * np.eye(len(self.observed))[None] / lam[:, None, None]
        chol = np.linalg.cholesky(cov)
        resid = np.linalg.solve(chol, (self.observed - mean)[..., None])[..., 0]
        loglike = -0.5 * np.sum(resid**2, axis=1) - np.log(np.diagonal(chol, axis1=1, axis2=2)).sum(axis=1)
        shape, rate = LAMBDA_Y_PRIOR
        out[inside] = loglike + shape * log_lam[inside] - rate * lam
        return out

    def initial_walkers(self, n_walkers: int, rng: np.random.Generator) -> np.ndarray:
        """Walkers spread uniformly over the box, lambda_y from its prior."""
        theta = rng.uniform(self.lower, self.upper, size=(n_walkers, len(self.names)))
        lam = rng.gamma(LAMBDA_Y_PRIOR[0], 1.0 / LAMBDA_Y_PRIOR[1], size=n_walkers)
        return np.column_stack([theta, np.log(lam)])


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


def sample(problem: Problem, n_samples: int, settings: dict, seed: int) -> tuple[pd.DataFrame, dict]:
    """Run the ensemble; return retained samples (theta, lambda_y, log_post, chain, step) and run info."""
    rng = np.random.default_rng(seed)
    chains = run_ensemble(problem.log_posterior, problem.initial_walkers(settings["walkers"], rng), n_samples,
                          settings["burn_in_steps"], settings["thin"], settings["mode_hop_fraction"], seed,
                          bounds=(problem.lower, problem.upper))
    walkers, steps, ndim = chains.samples.shape
    frame = pd.DataFrame(chains.samples.reshape(-1, ndim), columns=[*problem.names, "log_lambda_y"])
    frame["lambda_y"] = np.exp(frame.pop("log_lambda_y"))
    frame["log_post"] = chains.log_prob.reshape(-1)
    frame["chain"] = np.repeat(np.arange(walkers), steps)
    frame["step"] = np.tile(chains.steps, walkers)
    info = {"acceptance": chains.acceptance, "walkers": walkers, "burn_in_steps": settings["burn_in_steps"],
            "thin": settings["thin"], "retained": len(frame), "seed": seed}
    return frame, info


def summarize(samples: pd.DataFrame, names: list[str], units: dict) -> pd.DataFrame:
    """Per parameter: mean, sd, 5/50/95% quantiles, split R-hat, bulk/tail ESS, and a mixing flag."""
    rows = []
    n_chains = samples["chain"].nunique()
    for name in [*names, "lambda_y"]:
        draws = samples[name].to_numpy().reshape(n_chains, -1)
        q05, q50, q95 = np.quantile(draws, [0.05, 0.5, 0.95])
        rhat = split_rhat(draws)
        rows.append({"parameter": name, "unit": units.get(name, "-"), "mean": draws.mean(), "sd": draws.std(ddof=1),
                     "q05": q05, "q50": q50, "q95": q95, "r_hat": rhat, "ess_bulk": ess_bulk(draws),
                     "ess_tail": ess_tail(draws), "converged": bool(rhat <= RHAT_LIMIT)})
    summary = pd.DataFrame(rows)
    for row in summary[~summary["converged"]].itertuples():
        log.warning("parameter %s: R-hat %.3f > %.2f: the chains have not mixed; increase calibration.burn_in_steps "
                    "or n_samples, or calibration.walkers", row.parameter, row.r_hat, RHAT_LIMIT)
    return summary


def calibrate(emulator, shots, observed: pd.DataFrame, config: dict, source: str = "observed",
              **overrides) -> tuple[pd.DataFrame, pd.DataFrame, dict]:
    """Calibrate `shots` jointly (one shot = single-shot calibration): samples, summary, run info.

    `overrides` replace keys of config["calibration"] (e.g. n_samples, burn_in_steps, seed).
    """
    settings = {**config["calibration"], **overrides}
    problem = Problem.build(emulator, shots, observed, config["observed"]["sd_fraction"], source)
    check_observed_table(observed, shots, source, config["checks"]["observed_units"])
    n_samples = settings.get("n_samples") or settings["n_samples_single" if len(shots) == 1 else "n_samples_joint"]
    seed = settings.get("seed", config["study"]["seed"] + settings["seed_offset"])
    samples, info = sample(problem, n_samples, settings, seed)
    units = {k: config["inputs"][k]["unit"] for k in problem.names}
    summary = summarize(samples, problem.names, units)
    info.update(shots=list(shots), parameters=problem.names, units={**units, "lambda_y": "-"},
                observed=problem.observed.tolist(), observed_sd_m_s=problem.obs_sd.tolist())
    return samples, summary, info


def synthetic_truth(emulator, shots, config: dict, trials: int, seed: int, truths=None, **overrides) -> pd.DataFrame:
    """Calibrate on synthetic truth with a known theta; one row per trial and parameter.

    Each trial draws lambda_y from its prior and takes theta and noise-free features either from the
    emulator (theta uniform on the box, features from its predictive distribution at theta) or, when
    `truths` is given, from hydrocode runs (`HydroTruths`: theta of each run and its extracted
    features). Observation noise of sd = sd_fraction / sqrt(lambda_y) of each feature is added and
    the features are calibrated (`overrides` as in `calibrate`). Columns: trial, parameter, truth,
    q05, q95, inside (the 90% interval holds the truth), r_hat.
    """
    rng = np.random.default_rng(seed)
    names = emulator.required_inputs(shots)
    sd_fraction = config["observed"]["sd_fraction"]
    draw_truth = _emulator_truth(emulator, shots, names, rng) if truths is None else truths.draws(names, shots)
    rows = []
    for trial in range(trials):
        theta, lam, y = _noisy_truth(draw_truth, sd_fraction, rng)
        observed = pd.DataFrame(y.reshape(len(shots), -1), columns=emulator.feature_names).assign(shot=list(shots))
        _, summary, _ = calibrate(emulator, shots, observed, config, source=f"synthetic trial {trial}",
                                  seed=int(rng.integers(2**31)), **overrides)
        summary = summary.set_index("parameter")
        for name, truth in [*zip(names, theta), ("lambda_y", lam)]:
            q05, q95 = summary.loc[name, ["q05", "q95"]]
            rows.append({"trial": trial, "parameter": name, "truth": truth, "q05": q05, "q95": q95,
                         "inside": bool(q05 <= truth <= q95), "r_hat": summary.loc[name, "r_hat"]})
        log.info("synthetic trial %d/%d done", trial + 1, trials)
    return pd.DataFrame(rows)


def _noisy_truth(draw_truth, sd_fraction, rng):
    """(theta, lambda_y, pseudo-measured features): the next truth with lambda_y from its prior and
    noise of sd = sd_fraction / sqrt(lambda_y) of each feature. A draw with a non-positive feature
    (no measurement reports one) is replaced by the next truth."""
    for theta, eta in draw_truth:
        lam = rng.gamma(LAMBDA_Y_PRIOR[0], 1.0 / LAMBDA_Y_PRIOR[1])
        y = eta + sd_fraction * np.abs(eta) / np.sqrt(lam) * rng.normal(size=eta.shape)
        if np.all(y > 0):
            return theta, lam, y
        log.info("synthetic truth with a non-positive feature: replaced by the next draw")
    raise InputError("synthetic truth: no draws left for the requested number of trials")


def _emulator_truth(emulator, shots, names, rng):
    """Endless (theta, features): theta uniform on the box, features from the emulator's predictive
    distribution at theta."""
    lower, upper = emulator.input_bounds(names)
    while True:
        theta = rng.uniform(lower, upper)
        mean, cov = emulator.predict({k: np.array([v]) for k, v in zip(names, theta)}, shots)
        yield theta, rng.multivariate_normal(mean[0], cov[0])


@dataclass
class HydroTruths:
    """Hydrocode runs as synthetic truth: their design (theta per run) and, per shot, their features."""

    design: pd.DataFrame
    features: dict            # shot -> features table (run, status, feature columns)

    def draws(self, names, shots):
        """(theta, features) of each run, in run order, with every shot's features ok and positive."""
        table = self.design.set_index("run")
        for shot in shots:
            ok = self.features[shot].query("status == 'ok'").set_index("run")
            table = table.join(ok[CALIBRATION_FEATURES].add_prefix(f"{shot}:"), how="inner")
        columns = [f"{shot}:{f}" for shot in shots for f in CALIBRATION_FEATURES]
        usable = table[(table[columns] > 0).all(axis=1)]
        log.info("hydrocode truth: %d of %d runs usable (every shot ok, features positive)", len(usable), len(self.design))
        for _, row in usable.iterrows():
            yield row[names].to_numpy(float), row[columns].to_numpy(float)


def coverage_table(trials: pd.DataFrame) -> pd.DataFrame:
    """Per parameter: trials, share of 90% intervals holding the truth (nominal 0.90), largest R-hat."""
    return trials.groupby("parameter", sort=False).agg(trials=("trial", "nunique"), coverage90=("inside", "mean"),
                                                       max_r_hat=("r_hat", "max")).reset_index()


def coverage_check(emulator, shots, config: dict, trials: int | None = None,
                   truths: HydroTruths | None = None) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The configured synthetic-truth check (calibration.check), on emulator or hydrocode truth:
    per-trial table and coverage per parameter."""
    settings, check = config["calibration"], config["calibration"]["check"]
    table = synthetic_truth(emulator, shots, config, trials or check["trials"],
                            seed=config["study"]["seed"] + settings["seed_offset"] + 1, truths=truths,
                            n_samples=check["n_samples"], burn_in_steps=check["burn_in_steps"])
    return table, coverage_table(table)
