"""The hydrocode's verdict (shockcal.inference.verify): PSIS of the hydrocode-over-emulator likelihood ratios on toys
with a known truth, the hydrocode's likelihood as the emulator's with its share removed, and the emulator's error at
the draws in the records' sds."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats
from test_emulator import _fitted_and_unseen

from shockcal.errors import ConfigError, InputError
from shockcal.inference.problem import Problem
from shockcal.inference.settings import VerifySettings
from shockcal.inference.verify import corrected_quantiles, emulator_error_at_draws, khat_threshold, psis_verdict
from shockcal.study.validate import validate_config
from shockcal.velocimetry.columns import CALIBRATION_FEATURES

S = 4000


def gaussian_log_lik(theta, mean, sd):
    """A likelihood whose posterior under a flat prior is N(mean, sd^2)."""
    return stats.norm.logpdf(theta, mean, sd)


def test_a_shifted_emulator_posterior_is_corrected_to_the_true_one():
    """Draws from the emulator's posterior N(0.5, 1), the hydrocode's N(0, 1): k-hat passes and the corrected
    5/50/95% points are the true posterior's within 4 Monte Carlo sds, where the emulator's are 0.5 off."""
    theta = np.random.default_rng(1).normal(0.5, 1.0, S)
    verdict = psis_verdict(gaussian_log_lik(theta, 0.0, 1.0), gaussian_log_lik(theta, 0.5, 1.0))
    assert verdict.passed and verdict.khat < verdict.threshold == 0.7
    assert np.isclose(np.logaddexp.reduce(verdict.log_weights), 0.0)
    table = corrected_quantiles(theta[:, None], ["A"], verdict).iloc[0]
    truth = stats.norm.ppf([0.05, 0.5, 0.95])
    corrected = table[["corrected_q05", "corrected_q50", "corrected_q95"]].to_numpy(float)
    emulator = table[["emulator_q05", "emulator_q50", "emulator_q95"]].to_numpy(float)
    ess = 1.0 / np.sum(np.exp(verdict.log_weights) ** 2)
    mc_sd = np.sqrt([0.05 * 0.95, 0.25, 0.05 * 0.95]) / stats.norm.pdf(truth) / np.sqrt(ess)
    assert np.all(np.abs(corrected - truth) < 4 * mc_sd), (corrected, truth, mc_sd)
    assert np.all(np.abs(emulator - truth) > 0.4)                # the toy could fail: the uncorrected points are off
    assert table["median_shift_sd"] == pytest.approx(-0.5, abs=0.1)


def test_an_emulator_posterior_far_narrower_than_the_hydrocodes_fails_in_one_line():
    """Draws from N(0, 0.2^2) where the hydrocode's posterior is N(1, 1): the weights' tail is heavy, k-hat is above
    its threshold, the corrected points are not reported and the verdict says what it means."""
    theta = np.random.default_rng(2).normal(0.0, 0.2, S)
    verdict = psis_verdict(gaussian_log_lik(theta, 1.0, 1.0), gaussian_log_lik(theta, 0.0, 0.2))
    assert not verdict.passed and verdict.khat > verdict.threshold
    line = verdict.line()
    assert "\n" not in line and "the emulator misleads in the posterior region" in line and "design.waves" in line
    weights = np.exp(verdict.log_weights)                     # the line says why: few effective draws, sharp L_hydro
    assert 1.0 <= verdict.raw_ess < 0.1 * S and verdict.largest_weight > 1.0 / S
    assert verdict.log_lik_sd_hydrocode == pytest.approx(np.std(gaussian_log_lik(theta, 1.0, 1.0)), rel=1e-12)
    assert verdict.log_lik_sd_emulator == pytest.approx(np.std(gaussian_log_lik(theta, 0.0, 0.2)), rel=1e-12)
    assert f"Kish ESS {verdict.raw_ess:.1f} of {S}" in line and weights.sum() == pytest.approx(1.0)
    table = corrected_quantiles(theta[:, None], ["A"], verdict)
    assert table["corrected_q50"].isna().all() and not table["passed"].any()


def test_khat_threshold_follows_the_number_of_draws():
    """min(1 - 1/log10(S), 0.7): 0.28 at 25 draws, 0.6 at 300, 0.7 from 10^(10/3) ~ 2154 on."""
    assert khat_threshold(25) == pytest.approx(1 - 1 / np.log10(25))
    assert khat_threshold(300) == pytest.approx(0.5963, abs=1e-4)
    assert khat_threshold(5000) == 0.7


def test_bad_input_is_refused_in_one_line(paper_config):
    """The library refuses what the config refuses: fewer than 25 draws (ArviZ's k-hat needs a tail of 5 of the
    S/5 largest weights), in one line naming the key."""
    paper_config["verify"] = {"n_draws": 10}
    with pytest.raises(ConfigError, match=r"verify\.n_draws: 10 is less than the minimum of 25"):
        validate_config(paper_config, source="config.yaml")
    with pytest.raises(InputError, match="calibration.discrepancy is 'feature_kind': the hydrocode's verdict does not"):
        VerifySettings(n_draws=300, discrepancy={"kind": "feature_kind", "sd_fraction_prior": 0.02})
    assert VerifySettings(discrepancy={"kind": "none"}).n_draws == VerifySettings(discrepancy=None).n_draws == 300
    with pytest.raises(InputError, match=r"VerifySettings\.n_draws 10: Input should be greater than or equal to 25"):
        VerifySettings(n_draws=10)
    with pytest.raises(InputError, match="one of each per draw"):
        psis_verdict(np.zeros(30), np.zeros(31))
    with pytest.raises(InputError, match="at least 25"):
        psis_verdict(np.zeros(10), np.zeros(10))
    bad = np.zeros(30)
    bad[7] = np.nan
    with pytest.raises(InputError, match="draw 7: a log-likelihood is not finite"):
        psis_verdict(bad, np.zeros(30))


def test_the_hydrocodes_likelihood_is_the_samplers_without_the_emulators_share():
    """With the emulator's covariance set to zero, the sampler's log-likelihood is the hydrocode's at the same
    features and lambda_y (the observation and read-out sd over lambda_y); with it, the noise adds the emulator's
    variance."""
    rng = np.random.default_rng(3)
    observed = np.array([100.0, 250.0, 400.0])
    features = observed * (1 + 0.01 * rng.normal(size=(5, 3)))
    lam = rng.gamma(5.0, 0.2, 5)
    cov = np.broadcast_to(np.diag([4.0, 9.0, 16.0]), (5, 3, 3))

    def problem(covariance):
        def predict(theta):
            return features[theta[:, 0].astype(int)], covariance
        return Problem(predict, observed, 0.01 * observed, ["i"], np.array([0.0]), np.array([4.0]))

    points = np.column_stack([np.arange(5.0), lam])
    hydro = problem(np.zeros((5, 3, 3))).hydrocode_log_likelihood(features, lam)
    np.testing.assert_allclose(problem(np.zeros((5, 3, 3))).log_likelihood(points), hydro, rtol=1e-12)
    expected = stats.norm.logpdf(observed, features, 0.01 * observed / np.sqrt(lam)[:, None]).sum(axis=1)
    np.testing.assert_allclose(hydro, expected, rtol=1e-12)
    with_share = stats.norm.logpdf(observed, features, np.sqrt((0.01 * observed) ** 2 / lam[:, None] + [4, 9, 16]))
    np.testing.assert_allclose(problem(cov).log_likelihood(points), with_share.sum(axis=1), rtol=1e-12)


def test_the_emulators_error_at_the_draws_is_read_in_the_records_sds(paper_config):
    """At 200 runs the emulator never saw, with the hydrocode's features set to its mean plus known offsets: each
    feature's RMSE in records' sds is the offset over that sd, the overall the root mean square of those, and the
    line names the feature furthest off; failed runs are not scored, a records' sd per feature is required."""
    emulator, new, new_features = _fitted_and_unseen(paper_config)
    mean, _ = emulator.predict({k: new[k].to_numpy() for k in new.columns}, ["104S"])
    offset, records_sd = np.array([0.3, 2.0, 0.5, 1.0]), np.array([1.0, 1.0, 2.0, 4.0])
    shifted = new_features.copy()
    shifted[CALIBRATION_FEATURES] = mean - offset
    shifted["status"] = np.where(shifted["run"] < 5, "failed", "ok")
    error = emulator_error_at_draws(emulator, new, {"104S": shifted}, records_sd)
    table = error.table
    np.testing.assert_allclose(table["rmse_m_s"].iloc[:-1], offset, rtol=1e-9)
    np.testing.assert_allclose(table["rmse_records_sd"].iloc[:-1], offset / records_sd, rtol=1e-9)
    assert error.rmse_records_sd == pytest.approx(np.sqrt(np.mean((offset / records_sd) ** 2)), rel=1e-9)
    assert error.rmse_m_s == pytest.approx(np.sqrt(np.mean(offset ** 2)), rel=1e-9)
    assert table["records_sd_m_s"].iloc[-1] == pytest.approx(np.sqrt(np.mean(records_sd ** 2)))
    assert table["n_values"].iloc[0] == 195 and 0.0 <= error.region <= 1.0
    line = error.line()
    assert "\n" not in line and "195 draws" in line and "1 of 4 features above 1" in line
    assert f"the most 104S:{CALIBRATION_FEATURES[1]} 2.00" in line
    with pytest.raises(InputError, match="3 records' sds for 4 features"):
        emulator_error_at_draws(emulator, new, {"104S": shifted}, records_sd[:3])
