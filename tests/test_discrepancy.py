"""The discrepancy term (calibration.discrepancy, issue 63): its likelihood, its prior, its refusals."""

import numpy as np
import pytest
from scipy import stats

from shockcal.emulator.error_model import ErrorModel
from shockcal.errors import InputError
from shockcal.inference.discrepancy import Discrepancy, from_setting
from shockcal.inference.problem import Problem

FEATURES = ("v_a", "v_b")
OBSERVED = np.array([100.0, 250.0, 110.0, 240.0])   # two shots x two feature kinds, m/s


def linear_predict(theta):
    """A stand-in emulator: mean linear in theta, a fixed covariance."""
    mean = np.column_stack([100 + theta[:, 0], 250 + theta[:, 1], 110 + theta[:, 0], 240 - theta[:, 1]])
    cov = np.diag([4.0, 9.0, 1.0, 16.0]) + 0.5
    return mean, np.broadcast_to(cov, (len(theta), 4, 4)).copy()


def problem(discrepancy=None, groups=None):
    return Problem(linear_predict, OBSERVED, 0.01 * OBSERVED, ["a", "b"], np.array([-5.0, -5.0]),
                   np.array([5.0, 5.0]), "test", groups, discrepancy)


def test_likelihood_with_discrepancy_is_the_multivariate_normal_density():
    disc = Discrepancy(FEATURES, 2)
    points = np.array([[1.0, -2.0, 0.8, 0.03, 0.01, 0.6], [-3.0, 4.0, 1.3, 0.005, 0.04, 0.1]])
    got = problem(disc).log_likelihood(points)
    for point, value in zip(points, got):
        mean, cov = linear_predict(point[None, :2])
        f_a, f_b, rho = point[3:]
        sd = np.array([f_a, f_b, f_a, f_b]) * OBSERVED
        corr = np.array([[1, 0, rho, 0], [0, 1, 0, rho], [rho, 0, 1, 0], [0, rho, 0, 1]])
        total = cov[0] + np.outer(sd, sd) * corr + np.diag((0.01 * OBSERVED) ** 2 / point[2])
        assert value == pytest.approx(stats.multivariate_normal(mean[0], total).logpdf(OBSERVED), rel=1e-12)


def test_discrepancy_none_leaves_the_log_likelihood_bit_identical():
    points = np.array([[1.0, -2.0, 0.8], [-3.0, 4.0, 1.3]])
    mean, cov = linear_predict(points[:, :2])
    noise_var = (0.01 * OBSERVED) ** 2 / points[:, 2:]
    expected = ErrorModel().log_density(OBSERVED - mean, cov, noise_var)
    plain = problem()
    assert np.array_equal(plain.log_likelihood(points), expected)
    assert plain.ndim == 3 and plain.discrepancy_names == []
    assert from_setting("none", FEATURES, 2) is None and from_setting(None, FEATURES, 2) is None


def test_prior_transform_maps_the_cube_to_the_declared_priors():
    disc = Discrepancy(FEATURES, 2, sd_fraction_prior=0.03)
    p = problem(disc)
    assert p.ndim == 6
    assert p.discrepancy_names == ["delta_sd_fraction_v_a", "delta_sd_fraction_v_b", "delta_rho_shots"]
    u = np.random.default_rng(3).uniform(size=(4000, 6))
    x = p.prior_transform(u)
    assert np.array_equal(x[:, :3], problem().prior_transform(u[:, :3]))        # theta and lambda_y unchanged
    for j in (3, 4):
        assert stats.kstest(x[:, j], stats.halfnorm(scale=0.03).cdf).pvalue > 1e-3
        assert np.median(x[:, j]) == pytest.approx(0.03 * stats.halfnorm.ppf(0.5), rel=0.05)
    assert stats.kstest(x[:, 5], stats.uniform(0, 1).cdf).pvalue > 1e-3
    assert np.all(x[:, 3:5] >= 0) and np.all((x[:, 5] >= 0) & (x[:, 5] <= 1))    # inside the priors' support


def test_student_t_blocks_are_refused_with_a_discrepancy():
    groups = [(np.arange(4), ErrorModel(dof=5.0, scale=1.2))]
    with pytest.raises(InputError, match="needs Gaussian emulator errors"):
        problem(Discrepancy(FEATURES, 2), groups).log_likelihood(np.array([[0.0, 0.0, 1.0, 0.02, 0.02, 0.5]]))


@pytest.mark.parametrize("setting, message", [
    ("gp", "give 'none'"),
    ({"kind": "gp"}, r"kind 'gp': Input should be 'none' or 'feature_kind'"),
    ({"kind": "feature_kind", "sd_fraction_prior": -0.1}, r"sd_fraction_prior -0.1: Input should be greater than 0"),
    ({"kind": "feature_kind", "sd_fraction_prior": "a lot"}, "sd_fraction_prior 'a lot': not a number"),
    ({"kind": "feature_kind", "rho": 0.5}, "rho 0.5: Extra inputs are not permitted"),
    (3, "give 'none'"),
    ({"kind": "feature_kind", "sd_fraction_prior": 0.8}, "less than or equal to 0.5"),
])
def test_wrong_settings_are_refused_in_one_line(setting, message):
    with pytest.raises(InputError, match=message) as info:
        from_setting(setting, FEATURES, 2)
    assert "\n" not in str(info.value)


@pytest.mark.parametrize("setting", ["gp", {"kind": "gp"}, {"kind": "feature_kind", "sd_fraction_prior": -0.1},
                                     {"kind": "feature_kind", "rho": 0.5},
                                     {"kind": "feature_kind", "sd_fraction_prior": 0.8}])
def test_the_config_refuses_what_the_library_refuses(paper_config, setting):
    from shockcal.errors import ConfigError
    from shockcal.study.validate import validate_config

    paper_config["calibration"]["discrepancy"] = setting
    with pytest.raises(ConfigError, match="calibration") as info:
        validate_config(paper_config, source="config.yaml")
    assert "\n" not in str(info.value)
    with pytest.raises(InputError):
        from_setting(setting, FEATURES, 2)


def test_the_config_default_is_none_and_a_mapping_is_taken(paper_config_readonly, paper_config):
    from shockcal.study.validate import validate_config

    assert paper_config_readonly["calibration"]["discrepancy"] == "none"
    paper_config["calibration"]["discrepancy"] = {"kind": "feature_kind", "sd_fraction_prior": 0.03}
    setting = validate_config(paper_config, source="config.yaml")["calibration"]["discrepancy"]
    assert from_setting(setting, FEATURES, 3) == Discrepancy(FEATURES, 3, 0.03)

