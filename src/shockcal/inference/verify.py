"""The hydrocode's verdict on a posterior (`make verify`, docs/calibration.md, "The hydrocode's verdict").

S draws of the joint posterior, made with the emulator's likelihood, are run through the hydrocode. Each draw's
importance ratio is the hydrocode's likelihood over the emulator's (the same error model: the observation sd and
read-out sd scaled by the draw's lambda_y, without the emulator's share), log w = log L_hydro - log L_emulator.
ArviZ's Pareto-smoothed importance sampling (PSIS; Vehtari et al. 2024) smooths the weights and gives k-hat, the
shape of their tail: below min(1 - 1/log10(S), 0.7) the smoothed weights correct the posterior's quantiles
reliably; above it, the emulator's posterior and the hydrocode's differ too much for any reweighting, and the
emulator misleads in the posterior region. How far it misleads: its error at the same draws, which no fit saw,
against the records' sd (`emulator_error_at_draws`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from shockcal.errors import InputError
from shockcal.inference.settings import MIN_VERIFY_DRAWS
from shockcal.inference.summaries import SUMMARY_QUANTILES, weighted_quantiles

FAILED_VERDICT = ("k-hat {khat:.2f} > {threshold:.2f} (S = {n}): the emulator misleads in the posterior region "
                  "(its error there: the next line); training runs placed there (another wave, design.waves) "
                  "shrink that error (the corrected quantiles are not reported)")
WEIGHTS_NOTE = ("; raw weights: Kish ESS {ess:.1f} of {n}, the largest {largest:.2f}; log-likelihood sd over the "
                "draws: emulator {sd_emulator:.1f}, hydrocode {sd_hydrocode:.1f}")


@dataclass(frozen=True)
class Verdict:
    """PSIS of the hydrocode-over-emulator importance ratios: k-hat, its threshold for S draws, the smoothed log
    weights (normalised: logsumexp = 0), one per draw, and what says why a verdict failed: the raw weights' Kish
    effective sample size and largest normalised weight, and the sd over the draws of each log-likelihood (a
    hydrocode sd far above the emulator's: the hydrocode's posterior is much narrower than the emulator's)."""

    khat: float
    threshold: float
    log_weights: np.ndarray
    raw_ess: float = float("nan")
    largest_weight: float = float("nan")
    log_lik_sd_emulator: float = float("nan")
    log_lik_sd_hydrocode: float = float("nan")

    @property
    def n_draws(self) -> int:
        return len(self.log_weights)

    @property
    def passed(self) -> bool:
        return bool(self.khat <= self.threshold)

    def line(self) -> str:
        """One line for the log and the report."""
        if self.passed:
            return (f"k-hat {self.khat:.2f} <= {self.threshold:.2f} (S = {self.n_draws}): the hydrocode-corrected "
                    "quantiles are reliable")
        return (FAILED_VERDICT.format(khat=self.khat, threshold=self.threshold, n=self.n_draws)
                + WEIGHTS_NOTE.format(ess=self.raw_ess, n=self.n_draws, largest=self.largest_weight,
                                      sd_emulator=self.log_lik_sd_emulator, sd_hydrocode=self.log_lik_sd_hydrocode))


def khat_threshold(n_draws: int) -> float:
    """The largest k-hat at which PSIS with `n_draws` draws is reliable: min(1 - 1/log10(S), 0.7)
    (Vehtari et al. 2024, "Pareto smoothed importance sampling", JMLR 25)."""
    return float(min(1.0 - 1.0 / np.log10(n_draws), 0.7))


def psis_verdict(log_lik_hydrocode, log_lik_emulator) -> Verdict:
    """PSIS of the importance ratios L_hydrocode / L_emulator at S posterior draws.

    Args:
        log_lik_hydrocode: (S,) the log-likelihood of the measured features with the hydrocode's features at each
            draw (`Problem.hydrocode_log_likelihood`).
        log_lik_emulator: (S,) the log-likelihood the sampler used at the same draws (`Problem.log_likelihood`).

    A length mismatch, fewer than MIN_VERIFY_DRAWS draws or a non-finite value is an InputError.
    """
    import arviz

    hydro = np.asarray(log_lik_hydrocode, dtype=float)
    emulator = np.asarray(log_lik_emulator, dtype=float)
    if hydro.shape != emulator.shape or hydro.ndim != 1:
        raise InputError(f"verify: {hydro.shape} hydrocode log-likelihoods against {emulator.shape} emulator ones; "
                         "give one of each per draw")
    if len(hydro) < MIN_VERIFY_DRAWS:
        raise InputError(f"verify: {len(hydro)} draws; PSIS needs at least {MIN_VERIFY_DRAWS}")
    bad = ~(np.isfinite(hydro) & np.isfinite(emulator))
    if bad.any():
        raise InputError(f"verify: draw {int(np.argmax(bad))}: a log-likelihood is not finite")
    log_ratio = hydro - emulator
    smoothed, khat = arviz.psislw(log_ratio - log_ratio.max())
    raw = np.exp(log_ratio - log_ratio.max())
    raw /= raw.sum()
    return Verdict(float(np.asarray(khat)), khat_threshold(len(hydro)), np.asarray(smoothed, dtype=float),
                   raw_ess=float(1.0 / np.sum(raw ** 2)), largest_weight=float(raw.max()),
                   log_lik_sd_emulator=float(emulator.std()), log_lik_sd_hydrocode=float(hydro.std()))


def corrected_quantiles(draws: np.ndarray, names: list[str], verdict: Verdict, quantiles=SUMMARY_QUANTILES
                        ) -> pd.DataFrame:
    """Per input: the emulator posterior's quantiles of the S draws (equal weights) and, where k-hat passes, the
    hydrocode-corrected ones (the smoothed weights; NaN where it fails), and their shift in the emulator posterior's
    sd. `draws` (S, d) in the units the table is wanted in."""
    draws = np.asarray(draws, dtype=float)
    weights = np.exp(verdict.log_weights)
    rows = []
    for j, name in enumerate(names):
        x = draws[:, j]
        row = {"parameter": name}
        before = weighted_quantiles(x, np.ones_like(x), quantiles)
        after = weighted_quantiles(x, weights, quantiles) if verdict.passed else np.full(len(quantiles), np.nan)
        for p, b, a in zip(quantiles, before, after):
            row[f"emulator_q{round(100 * p):02d}"], row[f"corrected_q{round(100 * p):02d}"] = b, a
        sd = np.std(x)
        row["median_shift_sd"] = (after[len(quantiles) // 2] - before[len(quantiles) // 2]) / sd if sd > 0 else 0.0
        rows.append(row)
    table = pd.DataFrame(rows)
    table["khat"], table["khat_threshold"], table["passed"] = verdict.khat, verdict.threshold, verdict.passed
    table["n_draws"] = verdict.n_draws
    return table


@dataclass(frozen=True)
class EmulatorError:
    """The emulator's error at the verify draws against the hydrocode's features, which no fit saw.

    table: per shot and feature (`feature` "shot:name") and over all of them (the last row), `score_heldout`'s
        columns with the records' sd: `rmse_m_s`, `coverage` of the error model's 90% band, `mean_z2`, `n_values`,
        `records_sd_m_s` (the observation and read-out sd at lambda_y = 1) and `rmse_records_sd`;
    region: the share of draws inside the error model's 90% region over each block's features (the lowest
        block's: the density the likelihood uses, `region_coverage`).
    """

    table: pd.DataFrame
    region: float

    @property
    def rmse_m_s(self) -> float:
        return float(self.table["rmse_m_s"].iloc[-1])

    @property
    def rmse_records_sd(self) -> float:
        return float(self.table["rmse_records_sd"].iloc[-1])

    def line(self) -> str:
        """One line: the error's size in m/s and in the records' sds, and whether the error model holds it."""
        features = self.table.iloc[:-1]
        worst = features.loc[features["rmse_records_sd"].idxmax()]
        above = int((features["rmse_records_sd"] > 1.0).sum())
        return (f"the emulator at the {int(features['n_values'].iloc[0])} draws: RMSE {self.rmse_m_s:.2f} m/s, "
                f"{self.rmse_records_sd:.2f} records' sds ({above} of {len(features)} features above 1, the most "
                f"{worst['feature']} {worst['rmse_records_sd']:.2f}); its 90% bands hold "
                f"{self.table['coverage'].iloc[-1]:.3f} of the features, its 90% region {self.region:.3f} of the draws")


def emulator_error_at_draws(emulator, design: pd.DataFrame, features: dict[str, pd.DataFrame],
                            records_sd_m_s) -> EmulatorError:
    """The emulator's error where the posterior lives: at the verify draws, against the hydrocode's features there.

    Args:
        emulator: the study's `Emulator`.
        design: the draws, a `run` column and the calibrated inputs (native units).
        features: shot -> the hydrocode's features at the draws (`run`, `status`, the features in m/s), in the
            calibration's shot order; a draw is scored where every shot's run is "ok".
        records_sd_m_s: (shots x features,) the records' sd (m/s, `Problem.obs_sd`), shot-major as the table.
    """
    from shockcal.emulator.heldout import region_coverage, score_heldout

    table = score_heldout(emulator, design, features, records_sd_m_s=records_sd_m_s)
    return EmulatorError(table, float(region_coverage(emulator, design, features)["coverage"].min()))
