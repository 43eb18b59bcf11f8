"""Leave-one-shot-out prediction (issue 63) against known truths: the Gaussian conditional, its coverage on
draws from the model, and the left-out shot's own inputs from the prior."""

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from shockcal.emulator.error_model import ErrorModel
from shockcal.errors import InputError
from shockcal.inference.leave_one_out import conditional_prediction, leave_one_shot_out, mixture_table


def random_cov(rng, f):
    a = rng.normal(size=(f, f))
    return a @ a.T + f * np.eye(f)


def test_conditional_matches_the_precision_matrix_form():
    """y_L | y_O from the joint precision P: mean m_L - P_LL^-1 P_LO (y_O - m_O), variance diag(P_LL^-1)."""
    rng = np.random.default_rng(3)
    cov = np.stack([random_cov(rng, 8) for _ in range(3)])
    mean, y, left = rng.normal(0, 5, (3, 8)), rng.normal(0, 5, 8), np.array([4, 5, 6, 7])
    got_mean, got_var = conditional_prediction(y, mean, cov, left)
    others = np.arange(4)
    for s in range(3):
        p = np.linalg.inv(cov[s])
        p_ll_inv = np.linalg.inv(p[np.ix_(left, left)])
        expected = mean[s, left] - p_ll_inv @ p[np.ix_(left, others)] @ (y[others] - mean[s, others])
        np.testing.assert_allclose(got_mean[s], expected, rtol=1e-10)
        np.testing.assert_allclose(got_var[s], np.diag(p_ll_inv), rtol=1e-10)


def test_features_drawn_from_the_model_fall_in_the_band_at_its_rate():
    """5,000 joint draws from one known Gaussian: the left-out features' PIT is uniform, 95% inside."""
    rng = np.random.default_rng(11)
    cov, mean = random_cov(rng, 6)[None], rng.normal(100, 10, (1, 6))
    left = np.array([0, 3])
    samples = rng.multivariate_normal(mean[0], cov[0], 5000)
    parts = [conditional_prediction(y, mean, cov, left) for y in samples]
    cond_mean = np.concatenate([m for m, _ in parts], axis=1)       # one draw, 10,000 features side by side
    cond_var = np.concatenate([v for _, v in parts], axis=1)
    table = mixture_table(samples[:, left].ravel(), cond_mean, cond_var)
    assert table["inside"].mean() == pytest.approx(0.95, abs=4 * np.sqrt(0.95 * 0.05 / len(table)))
    assert stats.kstest(table["pit"], "uniform").pvalue > 0.001


def test_mixture_table_z_and_band_for_one_draw():
    table = mixture_table(np.array([103.0]), np.array([[100.0]]), np.array([[4.0]]))
    assert table["z"].iloc[0] == pytest.approx(1.5)
    assert table["q_high_m_s"].iloc[0] == pytest.approx(100 + 2 * stats.norm.ppf(0.975))
    assert bool(table["inside"].iloc[0])


class LinearStandIn:
    """Two shots x two features; shot a reads inputs (x, va), shot b (x, vb); features = 100 (1 + x) + v."""

    feature_names = ("f1", "f2")

    def required_inputs(self, shots):
        return ["x", *[f"v{shot}" for shot in shots]]

    def predict(self, inputs, shots):
        n = len(inputs["x"])
        mean = np.column_stack([100 * (1 + inputs["x"]) + inputs[f"v{shot}"] * k
                                for shot in shots for k in (1.0, 2.0)])
        return mean, np.broadcast_to(np.eye(2 * len(shots)), (n, 2 * len(shots), 2 * len(shots))).copy()

    def error_groups(self, shots):
        return [(np.arange(2 * len(shots)), ErrorModel(np.inf, 4.0))]


def test_the_left_out_shots_own_input_is_drawn_from_its_prior_box():
    draws = pd.DataFrame({"x": np.full(4000, 0.5), "va": np.full(4000, 1.0), "lambda_y": 1.0})
    observed = np.array([151.0, 152.0, 150.0, 150.0])
    table = leave_one_shot_out(LinearStandIn(), ["a", "b"], "b", draws, observed, np.zeros(4), {"vb": (0.0, 10.0)}, 0)
    assert table["prior_inputs"].iloc[0] == "vb" and list(table["feature"]) == ["f1", "f2"]
    # vb uniform on [0, 10] moves f1 by vb and f2 by 2 vb around 150: means 155 and 160, sd sqrt(var_vb k^2 + 4)
    np.testing.assert_allclose(table["mean_m_s"], [155.0, 160.0], atol=0.3)
    np.testing.assert_allclose(table["sd_m_s"], np.sqrt(np.array([1.0, 4.0]) * 100 / 12 + 4.0), rtol=0.03)


def test_a_correlated_discrepancy_carries_the_other_shots_residual():
    """rho near 1 and a large fraction: shot a's features 10% above the model's pull shot b's prediction up by
    almost as much; without a discrepancy (independent errors) they do not."""
    observed = np.array([165.0, 165.0, 150.0, 150.0])
    base = pd.DataFrame({"x": np.full(200, 0.5), "va": 0.0, "vb": 0.0, "lambda_y": 1.0})
    bounds = {"vb": (0.0, 0.0)}
    without = leave_one_shot_out(LinearStandIn(), ["a", "b"], "b", base, observed, np.zeros(4), bounds, 0)
    np.testing.assert_allclose(without["mean_m_s"], 150.0, atol=1e-9)
    with_delta = base.assign(delta_sd_fraction_f1=0.2, delta_sd_fraction_f2=0.2, delta_rho_shots=0.999)
    table = leave_one_shot_out(LinearStandIn(), ["a", "b"], "b", with_delta, observed, np.zeros(4), bounds, 0)
    # Sigma_delta: sd 0.2 x 165 on a, 0.2 x 150 on b; cov(b, a) = rho sd_a sd_b; the emulator's 4 on each
    sd_a, sd_b = 33.0, 30.0
    expected = 150.0 + 0.999 * sd_a * sd_b / (sd_a ** 2 + 4.0) * 15.0
    np.testing.assert_allclose(table["mean_m_s"], expected, rtol=1e-9)


def test_refusals_name_the_problem():
    draws = pd.DataFrame({"x": [0.5], "lambda_y": [1.0]})
    with pytest.raises(InputError, match="'c' is not one of"):
        leave_one_shot_out(LinearStandIn(), ["a", "b"], "c", draws, np.zeros(4), np.zeros(4), {}, 0)
    with pytest.raises(InputError, match="no column 'va'"):
        leave_one_shot_out(LinearStandIn(), ["a", "b"], "b", draws, np.zeros(4), np.zeros(4), {}, 0)
    with pytest.raises(InputError, match="'vb' has no prior box"):
        leave_one_shot_out(LinearStandIn(), ["a", "b"], "b", draws.assign(va=0.0), np.zeros(4), np.zeros(4), {}, 0)
