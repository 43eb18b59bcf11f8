"""Synthetic-truth checks of the calibration: truths from the emulator or from hydrocode runs,
pseudo-measurements with the observation noise, and the coverage of the 90% intervals."""

from __future__ import annotations

import logging
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
import pandas as pd
from scipy import stats

from shockcal.errors import InputError, ShockcalError
from shockcal.inference.calibration import CalibrationSettings, calibrate
from shockcal.inference.problem import LAMBDA_Y, LAMBDA_Y_PRIOR, Problem, log_density, prior_box
from shockcal.progress import progress
from shockcal.velocimetry.columns import CALIBRATION_FEATURES

log = logging.getLogger("shockcal.inference.coverage")


def synthetic_truth(emulator, shots, settings: CalibrationSettings, trials, seed: int, truths=None,
                    draws: list | None = None) -> pd.DataFrame:
    """Calibrate on synthetic truth with a known theta; one row per trial and parameter.

    `trials` is a count or the trial numbers to run (a range): each trial draws from its own random
    stream (child `trial` of `seed`), so a check split into batches of trials (the workflow's jobs)
    gives the same rows as one run. A trial draws lambda_y from its prior and takes theta and
    noise-free features either from the emulator (theta uniform on the box, features from its
    predictive distribution at theta) or, when `truths` is given, from hydrocode run number `trial`
    among the usable ones (`HydroTruths`; its design's `lambda_y` when the design has one, e.g. truths
    drawn from a posterior). `truths` without features take theta from their design and the features
    from the emulator's predictive distribution there: the same truths as their hydrocode runs with a
    likelihood that is right by construction, so the two checks' difference is the emulator's.
    Observation noise of sd = sd_fraction / sqrt(lambda_y) of each feature is added and the features
    are calibrated with `settings` (the sampler reseeded from the trial's stream). With `draws` (a
    list), each finished trial's equal-weight posterior draws are appended to it as a table with
    `trial` and `run` columns. Columns:
    trial, run (the truth's hydrocode run; empty for emulator truth), parameter, truth, q05, q95, sd
    (posterior sd), inside (the 90% interval holds the truth), ess (Kish ESS),
    truth_hpd_mass (the trial's `hpd_mass` of the truth, the same on each of its rows; empty with a
    `calibration.discrepancy`, whose parameters the truth does not have: the intervals are the check), status ("ok" or
    "failed") and reason. A trial that fails (the sampler at `max_evaluations`, no positive noise draw)
    is recorded with its reason and empty results, and the next one runs; the coverage leaves it out
    (`usable_trials`) and counts it.
    """
    trial_ids = range(trials) if isinstance(trials, int) else trials
    names = emulator.required_inputs(shots)
    box = emulator.input_bounds(names)
    if settings.bounds is not None:        # truths on the prior box the calibration samples
        box = prior_box(names, settings.bounds, *box, f"synthetic truth of {'+'.join(shots)}", settings.units)
    hydro_draws = None if truths is None else truths.table(names, shots)
    if hydro_draws is not None and max(trial_ids, default=-1) >= len(hydro_draws):
        raise InputError(f"synthetic truth: trial {max(trial_ids)} needs hydrocode run number {max(trial_ids) + 1}, "
                         f"but only {len(hydro_draws)} truth runs are usable")
    rows = []
    batch = progress(trial_ids, len(trial_ids), f"synthetic trials {'+'.join(shots)}", "trial", log)
    for done, trial in enumerate(batch, 1):
        rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(trial,)))
        try:
            rows += _trial_rows(emulator, shots, names, settings, trial, rng, hydro_draws, box, draws)
        except ShockcalError as error:     # recorded and left out of the coverage, never the end of the batch
            log.warning("synthetic trial %d failed: %s", trial, error)
            rows += [{"trial": trial, "parameter": name, "status": "failed", "reason": str(error)}
                     for name in [*names, LAMBDA_Y]]
        log.debug("synthetic trial %d done (%d of %d)", trial, done, len(trial_ids))   # progress: count, time left
    table = pd.DataFrame(rows, columns=CHECK_COLUMNS)
    table["inside"] = table["inside"].astype("boolean")
    return table


CHECK_COLUMNS = ["trial", "run", "parameter", "truth", "q05", "q95", "sd", "inside", "ess", "truth_hpd_mass", "status",
                 "reason"]


def _trial_rows(emulator, shots, names, settings: CalibrationSettings, trial, rng, hydro_draws, box,
                draws: list | None = None) -> list[dict]:
    """One synthetic-truth trial: its truth, pseudo-measurement and calibration; a row per parameter."""
    if hydro_draws is None:
        theta, eta = _emulator_truth(emulator, shots, names, rng, box)
        run, lam = None, None
    else:
        theta, eta, run, lam = hydro_draws[trial]
        if eta is None:
            eta = _emulator_features(emulator, shots, names, theta, rng)
    lam, y = _noisy_features(eta, settings.sd_fraction, rng, trial, lam)
    observed = pd.DataFrame(y.reshape(len(shots), -1), columns=emulator.feature_names).assign(shot=list(shots))
    trial_settings = settings.with_sampler(seed=int(rng.integers(2**31)))
    posterior = calibrate(emulator, shots, observed, trial_settings, source=f"synthetic trial {trial}")
    draws_table, summary = posterior.draws, posterior.summary(native=True).set_index("parameter")
    if draws is not None:
        draws.append(draws_table.assign(trial=trial, run=run))
    if settings.discrepancy == "none":
        problem = Problem.for_shots(emulator, shots, observed, settings.sd_fraction)
        truth_ll = problem.log_likelihood(np.append(theta, lam)[None])[0]
        mass = hpd_mass(log_density(draws_table["log_likelihood"], draws_table[LAMBDA_Y]), log_density(truth_ll, lam))
    else:       # the truth has no discrepancy parameters to place in the posterior's joint density
        mass = float("nan")
    rows = []
    for name, truth in [*zip(names, theta), (LAMBDA_Y, lam)]:
        q05, q95 = summary.loc[name, ["q05", "q95"]]
        rows.append({"trial": trial, "run": run, "parameter": name, "truth": truth, "q05": q05, "q95": q95,
                     "sd": summary.loc[name, "sd"], "inside": bool(q05 <= truth <= q95), "ess": summary.loc[name, "ess"],
                     "truth_hpd_mass": mass, "status": "ok", "reason": ""})
    return rows


def hpd_mass(draw_log_density, truth_log_density: float) -> float:
    """Share of equal-weight posterior draws denser than the truth: the mass of the smallest credible
    region that holds it. Uniform on [0, 1] when the truths come from the prior and the posterior is
    right, whatever its shape; unlike the per-parameter intervals, one joint number per trial."""
    return float(np.mean(np.asarray(draw_log_density) > truth_log_density))


def _noisy_features(eta, sd_fraction, rng, trial, lam=None, attempts: int = 100):
    """(lambda_y, pseudo-measured features): lambda_y as given (the truth's) or from its prior, and noise
    of sd = sd_fraction / sqrt(lambda_y) of each feature. No measurement reports a non-positive feature:
    such a draw is drawn again (the features are conditioned on being positive)."""
    given = lam
    for _ in range(attempts):
        lam = rng.gamma(LAMBDA_Y_PRIOR[0], 1.0 / LAMBDA_Y_PRIOR[1]) if given is None else given
        y = eta + sd_fraction * np.abs(eta) / np.sqrt(lam) * rng.normal(size=eta.shape)
        if np.all(y > 0):
            return lam, y
    raise InputError(f"synthetic trial {trial}: {attempts} noise draws all gave a non-positive feature "
                     f"(noise-free features {np.round(eta, 3).tolist()})")


def _emulator_truth(emulator, shots, names, rng, box):
    """(theta, features): theta uniform on the prior box (lower, upper), features from the emulator's
    predictive distribution at theta (`_emulator_features`)."""
    lower, upper = box
    theta = rng.uniform(lower, upper)
    return theta, _emulator_features(emulator, shots, names, theta, rng)


def _emulator_features(emulator, shots, names, theta, rng) -> np.ndarray:
    """One draw of the features (F,) from the emulator's predictive distribution at theta (its error
    model's, block by block)."""
    mean, cov = emulator.predict({k: np.array([v]) for k, v in zip(names, theta)}, shots)
    features = np.empty(mean.shape[1])
    for cols, error in emulator.error_groups(shots):
        features[cols] = error.sample(mean[0, cols], cov[0, cols[:, None], cols[None, :]], rng)
    return features


class Truth(NamedTuple):
    """One hydrocode truth: its inputs, its runs' features (every shot's, m/s; None: the emulator's), its run
    id, its lambda_y or None."""

    theta: np.ndarray
    features: np.ndarray | None
    run: int
    lambda_y: float | None


@dataclass
class HydroTruths:
    """Hydrocode runs as synthetic truth: their design (theta per run) and, per shot, their features; without
    features (None), the design's inputs alone, the features drawn from the emulator (`synthetic_truth`)."""

    design: pd.DataFrame
    features: dict | None     # shot -> features table (run, status, feature columns)

    @classmethod
    def read(cls, design_path, feature_paths: dict | None, shots) -> HydroTruths:
        """From a design table and each shot's features table (CSV or Parquet); every shot calibrated
        needs its features. `feature_paths` None: the design alone."""
        from shockcal.io import check_unique, integer_ids, read_table, require_columns

        missing = [] if feature_paths is None else sorted(set(shots) - set(feature_paths))
        if missing:
            raise InputError(f"calibrate-check: no --truth-features for shot(s) {missing}")
        tables = {}
        for path in [design_path, *(feature_paths or {}).values()]:
            table = read_table(path)
            require_columns(table, ["run"] if path == design_path else ["run", "status", *CALIBRATION_FEATURES], path)
            tables[path] = integer_ids(table, "run", path)
            check_unique(tables[path], "run", path, "run")
        features = None if feature_paths is None else {shot: tables[path] for shot, path in feature_paths.items()}
        return cls(tables[design_path], features)

    def table(self, names, shots) -> list[Truth]:
        """A `Truth` per usable run (every shot's features ok and positive), in run order; its lambda_y is
        the design's `lambda_y` when it has one, else None (drawn from the prior). Without features, every
        design row is a truth, its features None."""
        from shockcal.io import require_columns

        require_columns(self.design, names, "truth design")
        table = self.design.set_index("run")
        for shot in shots if self.features is not None else []:
            ok = self.features[shot].query("status == 'ok'").set_index("run")
            table = table.join(ok[CALIBRATION_FEATURES].add_prefix(f"{shot}:"), how="inner")
        columns = [f"{shot}:{f}" for shot in shots for f in CALIBRATION_FEATURES] if self.features is not None else []
        usable = table[(table[columns] > 0).all(axis=1)].sort_index()
        if self.features is not None:
            log.info("hydrocode truth: %d of %d runs usable (every shot ok, features positive)", len(usable),
                     len(self.design))
        lam = usable[LAMBDA_Y].to_numpy(float) if LAMBDA_Y in usable else [None] * len(usable)
        features = usable[columns].to_numpy(float) if columns else [None] * len(usable)
        return [Truth(*row) for row in zip(usable[names].to_numpy(float), features, usable.index.to_numpy(int).tolist(),
                                           lam)]


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


def coverage_by_fifth(trials: pd.DataFrame, fifths: int = 5) -> pd.DataFrame:
    """Where the intervals miss: per parameter (rows) and fifth of its truths (columns, by rank: the
    lowest fifth of the truths first), the share of 90% intervals holding the truth, over the trials
    that finished. Truths drawn evenly over the box (a Latin hypercube, uniform draws) put each fifth
    of the truths in a fifth of the box; a method that is right everywhere gives about 0.90 in every
    cell, with a binomial sd of sqrt(0.09 / (trials / fifths)) (0.067 for 20 trials a cell). A fifth
    without a trial (fewer trials than fifths) is NaN."""
    usable = usable_trials(trials).astype({"inside": bool})
    columns = [f"{k}/{fifths}" for k in range(1, fifths + 1)]

    def by_rank(group: pd.DataFrame) -> pd.Series:
        rank = group["truth"].rank(method="first").to_numpy() - 1
        fifth = (rank * fifths // len(group)).astype(int)
        inside = group["inside"].to_numpy()
        return pd.Series([inside[fifth == k].mean() if np.any(fifth == k) else np.nan for k in range(fifths)], columns)

    return usable.groupby("parameter", sort=False)[["truth", "inside"]].apply(by_rank)


def joint_coverage(trials: pd.DataFrame) -> dict:
    """The joint check from the trials' `truth_hpd_mass`: the share of trials whose truth lies in the
    90% highest-density region, its central 95% binomial band, and the Kolmogorov-Smirnov p-value of
    the masses against the uniform distribution they follow for a calibrated method."""
    mass = usable_trials(trials).groupby("trial")["truth_hpd_mass"].first().to_numpy()
    band_low, band_high = binomial_band(len(mass))
    return {"trials": len(mass), "coverage90": float(np.mean(mass <= 0.9)), "band_low": band_low,
            "band_high": band_high, "uniform_ks_p": float(stats.kstest(mass, "uniform").pvalue)}


def paired_coverage(trials: pd.DataFrame, reference: pd.DataFrame) -> pd.DataFrame:
    """Two checks on the same truths compared trial by trial: `trials` (e.g. hydrocode features at
    posterior draws) against `reference` (the same draws' inputs with the emulator's features, a
    likelihood right by construction). Where the reference misses too, a miss is not the emulator's;
    the trials that differ tell the two apart.

    Per parameter, then `joint` (the truth in the 90% highest-density region; when both checks have
    `truth_hpd_mass`), over the trials both
    finished with the same run as truth: `trials`, `coverage90`, `reference_coverage90`, `only_here`
    and `only_reference` (trials covered by one check alone) and `mcnemar_p`, the exact two-sided
    McNemar p-value (binomial test of the discordant trials against 1/2; 1 with none). A run id that
    differs between the checks at a trial is an InputError: they are not on the same truths."""
    for table, which in ((trials, "the check"), (reference, "the reference")):
        if "run" not in table or table["run"].isna().all():
            raise InputError(f"paired coverage: {which} has no truth runs (emulator truth over the box); only checks "
                             "on the same truth runs pair up")
    keys = ["trial", "parameter"]
    both = usable_trials(trials).merge(usable_trials(reference), on=keys, suffixes=("", "_reference"))
    if both.empty:
        raise InputError("paired coverage: the two checks share no finished trial")
    other = both["run"].ne(both["run_reference"]) & both["run"].notna()
    if other.any():
        row = both[other].iloc[0]
        raise InputError(f"paired coverage: trial {row['trial']} has truth run {row['run']} in one check and "
                         f"{row['run_reference']} in the other; compare checks on the same truths")
    both = both.astype({"inside": bool, "inside_reference": bool})
    if {"truth_hpd_mass", "truth_hpd_mass_reference"} <= set(both) and both["truth_hpd_mass"].notna().all():
        joint = both.groupby("trial").first().reset_index().assign(
            parameter="joint", inside=lambda t: t["truth_hpd_mass"] <= 0.9,
            inside_reference=lambda t: t["truth_hpd_mass_reference"] <= 0.9)
        both = pd.concat([both, joint], ignore_index=True)
    rows = []
    for name, group in both.groupby("parameter", sort=False):
        here, there = group["inside"].to_numpy(bool), group["inside_reference"].to_numpy(bool)
        only_here, only_there = int(np.sum(here & ~there)), int(np.sum(there & ~here))
        discordant = only_here + only_there
        rows.append({"parameter": name, "trials": len(group), "coverage90": here.mean(),
                     "reference_coverage90": there.mean(), "only_here": only_here, "only_reference": only_there,
                     "mcnemar_p": stats.binomtest(only_here, discordant, 0.5).pvalue if discordant else 1.0})
    return pd.DataFrame(rows)


def binomial_band(trials):
    """The central 95% band of the share of `trials` (a count or an array of counts) that a
    calibrated 90% interval covers."""
    return stats.binom.ppf(0.025, trials, 0.9) / trials, stats.binom.ppf(0.975, trials, 0.9) / trials
