"""Calibration: the posterior against closed-form and two-mode answers, the density, bad input."""

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from shockcal.emulator.error_model import ErrorModel
from shockcal.errors import InputError
from shockcal.inference.calibration import calibrate
from shockcal.inference.problem import LAMBDA_Y_PRIOR, Problem, observed_vector
from shockcal.inference.sampler import SamplerSettings, sample
from shockcal.inference.summaries import SUMMARY_QUANTILES, quantile_mcse, weighted_quantiles
from shockcal.study.adapters import calibration_settings


class StandInEmulator:
    """An 'emulator' with a known mean function and a constant predictive covariance."""

    feature_names = ["v_elastic", "v_plastic"]

    def __init__(self, mean_fn, names, lower, upper, cov, error=None):
        self.mean_fn, self.names = mean_fn, names
        self.lower, self.upper, self.cov = np.array(lower, float), np.array(upper, float), np.asarray(cov, float)
        self.error = error or ErrorModel()

    def error_groups(self, shots):
        return [(np.arange(len(self.cov)), self.error)]

    def required_inputs(self, shots):
        return self.names

    def input_bounds(self, names):
        return self.lower, self.upper

    def predict(self, inputs, shots):
        theta = np.column_stack([inputs[k] for k in self.names])
        return self.mean_fn(theta), np.broadcast_to(self.cov, (len(theta), *self.cov.shape)).copy()


def _posterior_on_grid(problem, grids):
    """Unnormalised posterior on a grid over (theta..., log lambda_y), by brute force."""
    mesh = np.meshgrid(*grids, indexing="ij")
    points = np.column_stack([m.ravel() for m in mesh])
    logp = np.concatenate([problem.log_posterior(chunk) for chunk in np.array_split(points, 50)])
    weights = np.exp(logp - logp.max())
    return points, weights / weights.sum()


def _sample(problem, n_eff, seed, n_live=300):
    posterior = sample(problem, SamplerSettings(n_live=n_live, n_eff=n_eff, draws=20000, seed=seed))
    return posterior.draws, posterior.summary()


def _observed(y):
    return pd.DataFrame([{"shot": "S", "v_elastic": y[0], "v_plastic": y[1]}])


def test_linear_gaussian_posterior_mean_and_variance_match_the_exact_answer():
    H = np.array([[30.0, 5.0], [-4.0, 40.0]])
    emulator = StandInEmulator(lambda t: 100.0 + t @ H.T, ["a", "b"], [-1, -1], [1, 1], 0.25 * np.eye(2))
    problem = Problem.for_shots(emulator, ["S"], _observed([106.0, 108.0]), 0.01)
    samples, _ = _sample(problem, 1500, seed=5)
    points, weights = _posterior_on_grid(problem, [np.linspace(-0.2, 0.6, 121), np.linspace(-0.2, 0.6, 121),
                                                   np.linspace(-3.0, 2.5, 80)])
    for i, name in enumerate(["a", "b"]):
        exact_mean = weights @ points[:, i]
        exact_sd = np.sqrt(weights @ (points[:, i] - exact_mean) ** 2)
        draws = samples[name].to_numpy()
        assert abs(draws.mean() - exact_mean) < 4 * exact_sd / np.sqrt(1500) + 1e-3   # ESS >= 1500
        assert draws.std() == pytest.approx(exact_sd, rel=0.06)


def test_two_mode_posterior_is_found_in_the_right_proportion():
    # feature depends on theta^2 (modes near +0.55 and -0.65); the second feature favours one of them
    emulator = StandInEmulator(lambda t: np.column_stack([100 + 50 * t[:, 0] ** 2 + 5.0 * t[:, 0],
                                                          80 + 20 * t[:, 0] ** 2]),
                               ["a"], [-1], [1], 0.01 * np.eye(2))
    problem = Problem.for_shots(emulator, ["S"], _observed([118.0, 87.0]), 0.01)
    samples, _ = _sample(problem, 1500, seed=7)
    points, weights = _posterior_on_grid(problem, [np.linspace(-1, 1, 2001), np.linspace(-3.0, 2.5, 120)])
    exact_positive = weights[points[:, 0] > 0].sum()
    assert 0.2 < exact_positive < 0.8 and abs(exact_positive - 0.5) > 0.05  # both modes matter, unequally
    assert (samples["a"] > 0).mean() == pytest.approx(exact_positive, abs=0.04)
    assert samples["a"].abs().median() == pytest.approx(0.6, abs=0.05)


def test_lambda_y_prior_is_recovered_when_the_data_say_nothing():
    emulator = StandInEmulator(lambda t: np.column_stack([100 + 0 * t[:, 0], 80 + 0 * t[:, 0]]),
                               ["a"], [0], [1], 1e6 * np.eye(2))  # emulator so uncertain that y is uninformative
    problem = Problem.for_shots(emulator, ["S"], _observed([100.0, 80.0]), 0.01)
    samples, _ = _sample(problem, 1500, seed=3)
    prior = stats.gamma(LAMBDA_Y_PRIOR[0], scale=1 / LAMBDA_Y_PRIOR[1])
    assert samples["lambda_y"].mean() == pytest.approx(prior.mean(), rel=0.06)
    assert samples["a"].mean() == pytest.approx(0.5, abs=0.03)


def test_same_seed_gives_identical_samples():
    emulator = StandInEmulator(lambda t: 100.0 + 10 * t, ["a", "b"], [0, 0], [1, 1], np.eye(2))
    problem = Problem.for_shots(emulator, ["S"], _observed([105.0, 104.0]), 0.01)
    # the sampler's least settings (MIN_N_LIVE, MIN_N_EFF): a seed's reach does not depend on the run's size
    a, _ = _sample(problem, 100, seed=1, n_live=50)
    b, _ = _sample(problem, 100, seed=1, n_live=50)
    pd.testing.assert_frame_equal(a, b)


@pytest.mark.parametrize("table, message", [
    (pd.DataFrame([{"shot": "T", "v_elastic": 1.0, "v_plastic": 2.0}]), "no observed features for shot S"),
    (pd.DataFrame([{"shot": "S", "v_elastic": -1.0, "v_plastic": 2.0}]), r"\['v_elastic'\] missing or not positive"),
    (pd.DataFrame([{"shot": "S", "v_elastic": np.nan, "v_plastic": 2.0}]), "missing or not positive"),
    (pd.DataFrame([{"shot": "S", "v_elastic": 1.0}]), "missing column"),
])
def test_bad_observed_features_are_rejected(table, message):
    with pytest.raises(InputError, match=message):
        observed_vector(table, ["S"], ["v_elastic", "v_plastic"], "obs.csv")


def test_readout_sd_adds_to_the_observation_sd_in_quadrature():
    """The observed table's read-out sds (m/s) join the 1% in quadrature; a table without them is the 1%
    alone; a negative one is an error naming the shot and the column."""
    emulator = StandInEmulator(lambda t: 100.0 + 0 * t, ["a"], [0], [1], 0.25 * np.eye(2))
    plain = Problem.for_shots(emulator, ["S"], _observed([60.0, 200.0]), 0.01)
    assert plain.obs_sd == pytest.approx([0.6, 2.0])
    table = _observed([60.0, 200.0]).assign(readout_sd_v_elastic=0.8, readout_sd_v_plastic=0.0)
    assert Problem.for_shots(emulator, ["S"], table, 0.01).obs_sd == pytest.approx([1.0, 2.0])
    with pytest.raises(InputError, match="shot S: readout_sd_v_plastic"):
        Problem.for_shots(emulator, ["S"], table.assign(readout_sd_v_plastic=-1.0), 0.01, "obs.csv")


def test_calibrate_returns_draws_summary_and_evidence(paper_config):
    emulator = StandInEmulator(lambda t: np.column_stack([100 + 50 * t[:, 0] ** 2, 80 + 20 * t[:, 0] ** 2]),
                               ["A"], [-1], [1], 0.01 * np.eye(2))
    paper_config["inputs"]["A"] = {"min": -1, "max": 1, "unit": "Mbar"}
    paper_config["calibration"].update(n_live=50, n_eff=100, draws=1000)    # the least: the size is not checked
    settings = calibration_settings(paper_config, ["S"])
    posterior = calibrate(emulator, ["S"], _observed([118.0, 87.2]), settings)
    samples, summary, info = posterior.draws, posterior.summary(), posterior.info()
    assert len(samples) == 1000 and set(samples.columns) == {"A", "lambda_y", "log_likelihood"}
    assert list(summary["parameter"]) == ["A_MPa", "lambda_y"] and list(summary["unit"]) == ["MPa", "-"]
    row = summary.set_index("parameter").loc["A_MPa"]
    assert row["q05"] < row["q50"] < row["q95"] and row["ess"] >= 100 and info["ess_kish"] == row["ess"]
    native = posterior.summary(native=True)                   # as sampled: Mbar, the draws' unit
    assert list(native["parameter"]) == ["A", "lambda_y"] and list(native["unit"]) == ["Mbar", "-"]
    scaled = [c for c in native.columns if c not in ("parameter", "unit", "ess")]
    np.testing.assert_allclose(summary.loc[0, scaled].to_numpy(float), 1e5 * native.loc[0, scaled].to_numpy(float),
                               rtol=1e-12)
    np.testing.assert_array_equal(summary.loc[1, scaled].to_numpy(float), native.loc[1, scaled].to_numpy(float))
    assert info["user_units"] == {"A": "MPa", "lambda_y": "-"}
    assert info["parameters"] == ["A"] and np.isfinite(info["log_evidence"]) and info["likelihood_evaluations"] > 800


def test_cube_power_of_an_input_not_calibrated_is_an_error_naming_it():
    emulator = StandInEmulator(lambda t: np.column_stack([100 + 10 * t[:, 0], 80 + 0 * t[:, 0]]), ["a"], [0], [1],
                               np.eye(2))
    problem = Problem.for_shots(emulator, ["S"], _observed([105.0, 80.0]), 0.01)
    np.testing.assert_array_equal(problem.cube_power({"a": 2.0}), [2.0, 1.0])
    with pytest.raises(InputError, match=r"cube_power names \['m'\], not among the calibrated inputs \['a'\]"):
        problem.cube_power({"m": 2.0})
    np.testing.assert_array_equal(problem.cube_power({"m": 2.0, "a": 3.0}, others="ignore"), [3.0, 1.0])


def test_non_finite_likelihood_is_an_error_naming_the_point():
    def broken(t):
        mean = np.column_stack([100 + 10 * t[:, 0], 80 + 0 * t[:, 0]])
        mean[t[:, 0] > 0.5, 0] = np.nan
        return mean

    emulator = StandInEmulator(broken, ["a"], [0], [1], np.eye(2))
    problem = Problem.for_shots(emulator, ["S"], _observed([105.0, 80.0]), 0.01)
    with pytest.raises(InputError, match=r"not finite at \{'a': 0\.75"):
        problem.log_likelihood(np.array([[0.25, 1.0], [0.75, 1.0]]))
    with pytest.raises(InputError, match="not finite"):
        _sample(problem, 200, seed=1, n_live=100)


@pytest.mark.parametrize("weighted", [False, True], ids=["equal-weights", "importance-weights"])
def test_quantile_mcse_matches_the_spread_of_repeated_estimates(weighted):
    """Known truth: over 400 independent samples of a skewed posterior (a Gamma(2) here, its 95%
    quantile in a thin tail), the sd of each quantile estimate equals the reported Monte Carlo
    standard error within 15%, also with importance weights (proposal Gamma(2, scale 1.5)), whose
    loss of efficiency differs from quantile to quantile."""
    rng = np.random.default_rng(11)
    target, proposal = stats.gamma(2.0), stats.gamma(2.0, scale=1.5)
    estimates, errors = [], []
    for _ in range(400):
        if weighted:
            x = proposal.rvs(4000, random_state=rng)
            w = target.pdf(x) / proposal.pdf(x)
        else:
            x, w = target.rvs(2000, random_state=rng), np.ones(2000)
        w = w / w.sum()
        estimates.append(weighted_quantiles(x, w, SUMMARY_QUANTILES))
        errors.append(quantile_mcse(x, w, SUMMARY_QUANTILES))
    spread, reported = np.std(estimates, axis=0, ddof=1), np.mean(errors, axis=0)
    np.testing.assert_allclose(reported, spread, rtol=0.15)
    # and the estimates centre on the true quantiles within 3 standard errors of their mean
    truth = target.ppf(SUMMARY_QUANTILES)
    assert np.all(np.abs(np.mean(estimates, axis=0) - truth) < 3 * spread / np.sqrt(400))
