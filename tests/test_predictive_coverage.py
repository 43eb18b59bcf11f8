"""Posterior-predictive coverage with and without the discrepancy's share (issue 63) against known truths."""

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from shockcal.emulator.error_model import ErrorModel
from shockcal.errors import InputError
from shockcal.inference.predictive_coverage import mixture_quantile, predictive_coverage, study_predictive_coverage


def test_one_draw_gives_the_gaussian_band_and_pit():
    observed = np.array([101.0, 249.0, 80.0])
    mean = np.array([[100.0, 240.0, 80.0]])
    emulator, noise, delta = np.array([[1.0, 4.0, 0.25]]), np.array([[1.0, 1.0, 1.0]]), np.array([[2.0, 20.0, 0.0]])
    table = predictive_coverage(observed, mean, emulator, noise, delta)
    total = emulator + noise + delta
    z = stats.norm.ppf(0.975)
    np.testing.assert_allclose(table["q_low_m_s"], (mean - z * np.sqrt(total))[0], rtol=1e-12)
    np.testing.assert_allclose(table["q_high_m_s_without"], (mean + z * np.sqrt(emulator + noise))[0], rtol=1e-12)
    np.testing.assert_allclose(table["q50_m_s"], mean[0], rtol=1e-12)
    np.testing.assert_allclose(table["pit"], stats.norm.cdf((observed - mean[0]) / np.sqrt(total[0])), rtol=1e-12)
    # 249 against 240: 9 m/s is 4.0 sd without the discrepancy (outside its band), 1.8 sd with it (inside)
    assert list(table["inside"]) == [True, True, True] and list(table["inside_without"]) == [True, False, True]
    np.testing.assert_allclose(table["discrepancy_share"], [0.5, 20 / 25, 0.0])
    np.testing.assert_allclose(table["sd_discrepancy_m_s"], np.sqrt(delta[0]))


def test_mixture_quantile_inverts_the_mixture_cdf():
    rng = np.random.default_rng(1)
    mean, var = rng.normal(0, 3, (40, 5)), rng.uniform(0.5, 4, (40, 5))
    for p in (0.025, 0.5, 0.975):
        q = mixture_quantile(p, mean, var)
        np.testing.assert_allclose(stats.norm.cdf((q - mean) / np.sqrt(var)).mean(axis=0), p, atol=1e-12)


def test_coverage_is_nominal_with_the_discrepancy_and_short_by_the_known_amount_without():
    """Measurements drawn from the true predictive, a two-draw posterior mixture with a discrepancy of sd 3
    beside emulator and noise sd of 2 in all: their PIT is uniform, so 95% fall in the band with the
    discrepancy; without it, the band (the mixture of sd 2) holds a measurement from N(+-1, 13) with the
    probability of the normal CDF between its edges, about 0.78."""
    rng = np.random.default_rng(7)
    f = 20_000
    centres = np.array([[-1.0], [1.0]]) * np.ones((2, f))
    emulator, noise, delta = np.full((2, f), 1.5), np.full((2, f), 2.5), np.full((2, f), 9.0)
    component = rng.integers(0, 2, f)
    observed = centres[component, np.arange(f)] + rng.normal(0.0, np.sqrt(13.0), f)
    table = predictive_coverage(observed, centres, emulator, noise, delta)
    assert table["inside"].mean() == pytest.approx(0.95, abs=4 * np.sqrt(0.95 * 0.05 / f))
    assert stats.kstest(table["pit"], "uniform").pvalue > 0.001
    # without: the band is the two-component mixture of sd 2; a measurement from N(+-1, 13) falls in it with
    # a probability computed here from the band's edges (the same for every feature)
    low, high = table["q_low_m_s_without"].iloc[0], table["q_high_m_s_without"].iloc[0]
    expected = np.mean([stats.norm.cdf((high - c) / np.sqrt(13)) - stats.norm.cdf((low - c) / np.sqrt(13))
                        for c in (-1.0, 1.0)])
    assert 0.7 < expected < 0.85
    assert table["inside_without"].mean() == pytest.approx(expected, abs=4 * np.sqrt(expected * (1 - expected) / f))
    np.testing.assert_allclose(table["discrepancy_share"], 9 / 13)


def test_without_a_discrepancy_both_sides_agree_and_bad_parts_are_one_line_errors():
    mean = np.array([[100.0, 200.0]])
    table = predictive_coverage([101.0, 195.0], mean, [[1.0, 1.0]], [[1.0, 4.0]], shots=["104S"],
                                features=["v_a", "v_b"])
    assert list(table["shot"]) == ["104S", "104S"] and list(table["feature"]) == ["v_a", "v_b"]
    pd.testing.assert_series_equal(table["pit"], table["pit_without"], check_names=False)
    assert (table["discrepancy_share"] == 0).all()
    with pytest.raises(InputError, match=r"noise_var has shape \(1, 3\)"):
        predictive_coverage([1.0, 2.0], mean, [[1.0, 1.0]], [[1.0, 1.0, 1.0]])
    with pytest.raises(InputError, match="emulator_var has a value that is not finite or is negative"):
        predictive_coverage([1.0, 2.0], mean, [[-1.0, 1.0]], [[1.0, 1.0]])
    with pytest.raises(InputError, match="1 shots x 3 features for 2 values"):
        predictive_coverage([1.0, 2.0], mean, [[1.0, 1.0]], [[1.0, 1.0]], shots=["a"], features=["x", "y", "z"])


class StandIn:
    """A study emulator with two shots of two features, a fixed covariance and an error scale of 2."""

    feature_names = ["v_a", "v_b"]

    def required_inputs(self, shots):
        return ["a"]

    def check_inside(self, design, source):
        pass

    def predict(self, inputs, shots):
        a = inputs["a"]
        mean = np.column_stack([100 + a, 200 + a, 110 + a, 210 + a])
        return mean, np.broadcast_to(np.diag([1.0, 4.0, 9.0, 16.0]), (len(a), 4, 4)).copy()

    def error_groups(self, shots):
        return [(np.arange(4), ErrorModel(scale=2.0))]


def test_study_table_takes_the_design_s_lambda_y_and_sd_fractions():
    design = pd.DataFrame({"run": [0, 1], "a": [0.0, 2.0], "lambda_y": [1.0, 4.0],
                           "delta_sd_fraction_v_a": [0.01, 0.02], "delta_sd_fraction_v_b": [0.0, 0.03]})
    observed, sd = np.array([101.0, 201.0, 111.0, 211.0]), np.array([1.0, 2.0, 1.0, 2.0])
    table = study_predictive_coverage(StandIn(), design, ["s1", "s2"], observed, sd)
    emulator_var = 2.0 * np.array([1.0, 4.0, 9.0, 16.0])
    noise = sd**2 / np.array([[1.0], [4.0]])
    delta = (np.array([[0.01, 0.0, 0.01, 0.0], [0.02, 0.03, 0.02, 0.03]]) * observed) ** 2
    mean = np.array([[100.0, 200, 110, 210], [102, 202, 112, 212]])
    expected = predictive_coverage(observed, mean, np.tile(emulator_var, (2, 1)), noise, delta, ["s1", "s2"],
                                   ["v_a", "v_b"])
    pd.testing.assert_frame_equal(table, expected)
    without = study_predictive_coverage(StandIn(), design.drop(columns=["delta_sd_fraction_v_a",
                                                                        "delta_sd_fraction_v_b"]),
                                        ["s1", "s2"], observed, sd)
    assert (without["discrepancy_share"] == 0).all()
    with pytest.raises(InputError, match="delta_sd_fraction_v_b"):
        study_predictive_coverage(StandIn(), design.drop(columns=["delta_sd_fraction_v_b"]), ["s1", "s2"], observed, sd)
