"""The expected-information-gain estimator of `shockcal.campaign.next_shot` against truths it cannot tune to:
the closed forms of a linear-Gaussian problem (full and marginal), quadrature on a nonlinear toy,
the order of two designs, and bad input."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from shockcal.campaign.next_shot import expected_information_gain, noise_sd
from shockcal.errors import InputError


def _linear_problem():
    """theta ~ N(0, S) in 3-D, y = H theta + eps, eps ~ N(0, s^2 I) in 2-D."""
    rng = np.random.default_rng(123)
    a = rng.normal(size=(3, 3))
    return a @ a.T / 3 + 0.3 * np.eye(3), rng.normal(size=(2, 3))


def _linear_truth(cov, h, noise, targets):
    """I(theta; y) = 0.5 log det(I + S H' R^-1 H); I(theta_T; y) = 0.5 log(det S_TT / det P_TT) with P the
    posterior covariance (jointly Gaussian); the posterior sds."""
    full = 0.5 * np.linalg.slogdet(np.eye(len(cov)) + cov @ h.T @ h / noise**2)[1]
    post = cov - cov @ h.T @ np.linalg.solve(h @ cov @ h.T + noise**2 * np.eye(len(h)), h @ cov)
    t = np.ix_(targets, targets)
    return full, 0.5 * (np.linalg.slogdet(cov[t])[1] - np.linalg.slogdet(post[t])[1]), np.sqrt(np.diag(post))


def _linear_draws(cov, h, seed, n=200):
    rng = np.random.default_rng(seed)
    theta = rng.multivariate_normal(np.zeros(len(cov)), cov, size=n)
    return theta, theta @ h.T, rng


def test_linear_gaussian_full_and_marginal_against_closed_forms():
    cov, h = _linear_problem()
    full, marginal, post_sd = _linear_truth(cov, h, 0.5, [2])
    theta, g, rng = _linear_draws(cov, h, seed=0)
    result = expected_information_gain(g, np.full(2, 0.5), rng, targets=["c"], theta=theta, names=["a", "b", "c"])
    assert result.method == "gaussian-entropy-bound" and result.targets == ("c",)
    assert abs(result.eig_full - full) < 3 * result.eig_full_sd, (result.eig_full, result.eig_full_sd, full)
    assert abs(result.eig - marginal) < 3 * result.eig_sd, (result.eig, result.eig_sd, marginal)
    assert result.eig_full_lower < result.eig_full and result.resolved
    assert result.posterior_sd[0] == pytest.approx(post_sd[2], rel=0.1)
    everything = expected_information_gain(g, np.full(2, 0.5), np.random.default_rng(0))
    assert everything.method == "nmc-loo" and everything.targets is None and everything.posterior_sd is None


def test_linear_gaussian_z_scores_over_20_seeds_are_honest():
    # over seeds, (estimate - truth) / eig_sd: the full NMC's is centred (its O(1/N) bias is small here)
    # with sd near 1; the marginal is a lower bound, biased down by a few hundredths of a nat.
    cov, h = _linear_problem()
    full, marginal, _ = _linear_truth(cov, h, 0.5, [0, 2])
    z_full, z_marginal, bias = [], [], []
    for seed in range(20):
        theta, g, rng = _linear_draws(cov, h, seed=100 + seed)
        result = expected_information_gain(g, np.full(2, 0.5), rng, targets=[0, 2], theta=theta, n_boot=50)
        z_full.append((result.eig_full - full) / result.eig_full_sd)
        z_marginal.append((result.eig - marginal) / result.eig_sd)
        bias.append(result.eig - marginal)
    z_full, z_marginal = np.array(z_full), np.array(z_marginal)
    assert abs(z_full.mean()) < 1.0 and 0.5 < z_full.std() < 1.6, z_full
    assert np.mean(np.abs(z_full) < 3) >= 0.9
    assert -0.1 < np.mean(bias) < 0.02, bias          # a lower bound: never above the truth on average
    assert 0.5 < z_marginal.std() < 2.0, z_marginal
    assert np.mean(np.abs(z_marginal) < 3) >= 0.8, z_marginal


def test_too_informative_a_shot_is_bracketed_and_flagged():
    # EIG 4.1 nats with 200 draws: the LOO estimate is far above the truth, the PCE below; not resolved
    cov, h = _linear_problem()
    full, _, _ = _linear_truth(cov, h, 0.15, [0])
    theta, g, rng = _linear_draws(cov, h, seed=5)
    result = expected_information_gain(g, np.full(2, 0.15), rng)
    assert result.eig_full_lower < full < result.eig_full and not result.resolved


def _toy(theta):
    return (np.sin(theta[:, 0]) + theta[:, 1] ** 3)[:, None]


def _toy_sd(g):
    return 0.2 + 0.1 * np.abs(g)


def _toy_brute_force(sd1=1.0, sd2=0.7, n=121, ny=1500):
    """I(theta; y), I(theta1; y), I(theta2; y) by quadrature: y scalar, p(y), p(y | theta1), p(y | theta2) on
    grids of theta (+-6 sd, Gaussian prior weights) and y."""
    t1, t2 = np.linspace(-6 * sd1, 6 * sd1, n), np.linspace(-6 * sd2, 6 * sd2, n)
    w1, w2 = stats.norm.pdf(t1, 0, sd1), stats.norm.pdf(t2, 0, sd2)
    w1, w2 = w1 / w1.sum(), w2 / w2.sum()
    g = np.sin(t1)[:, None] + t2[None, :] ** 3
    s = _toy_sd(g)
    y = np.linspace((g - 8 * s).min(), (g + 8 * s).max(), ny)
    dens = stats.norm.pdf(y[None, None, :], g[:, :, None], s[:, :, None])          # (n, n, ny)

    def entropy(p):
        return -np.sum(p * np.log(np.maximum(p, 1e-300)), axis=-1) * (y[1] - y[0])

    h_y = entropy(np.einsum("i,j,ijy->y", w1, w2, dens))
    h_noise = np.sum(w1[:, None] * w2[None, :] * 0.5 * np.log(2 * np.pi * np.e * s**2))
    h_given_1 = w1 @ entropy(np.einsum("j,ijy->iy", w2, dens))
    h_given_2 = w2 @ entropy(np.einsum("i,ijy->jy", w1, dens))
    return h_y - h_noise, h_y - h_given_1, h_y - h_given_2


def test_nonlinear_toy_against_quadrature():
    # y = sin(theta1) + theta2^3 + eps, sd 0.2 + 0.1 |g| per draw; theta1 ~ N(0, 1), theta2 ~ N(0, 0.7^2)
    full, first, second = _toy_brute_force()     # 1.422, 0.456, 0.512 nats
    rng = np.random.default_rng(7)
    theta = np.column_stack([rng.normal(0, 1.0, 400), rng.normal(0, 0.7, 400)])
    g = _toy(theta)
    result = expected_information_gain(g, _toy_sd(g), rng, theta=theta)
    assert abs(result.eig - full) < 3 * result.eig_sd, (result.eig, result.eig_sd, full)
    assert result.eig_full_lower < full + 3 * result.eig_sd
    for target, truth in ((0, first), (1, second)):
        marginal = expected_information_gain(g, _toy_sd(g), rng, targets=[target], theta=theta)
        assert marginal.eig < truth + 3 * marginal.eig_sd, (target, marginal.eig, marginal.eig_sd, truth)
        assert marginal.eig > 0.6 * truth, (target, marginal.eig, truth)    # the bound's gap: non-Gaussian posteriors


def test_a_more_informative_design_ranks_above_beyond_noise():
    cov, h = _linear_problem()
    theta, g, rng = _linear_draws(cov, h, seed=3)
    sharp = expected_information_gain(g, np.full(2, 0.4), rng, targets=[2], theta=theta)
    blurred = expected_information_gain(g, np.full(2, 1.2), rng, targets=[2], theta=theta)
    for better, worse in ((sharp.eig_full, blurred.eig_full), (sharp.eig, blurred.eig)):
        assert better - worse > 3 * np.hypot(sharp.eig_sd, blurred.eig_sd), (better, worse)
    assert sharp.posterior_sd[0] < blurred.posterior_sd[0] < blurred.prior_sd[0]


def test_noise_sd_adds_readout_in_quadrature():
    g = np.array([[100.0, 200.0], [300.0, 400.0]])
    sd = noise_sd(g, 0.01, readout_sd=[3.0, 0.0], lambda_y=[1.0, 4.0])
    assert np.allclose(sd, [[np.hypot(1.0, 3.0), 2.0], [np.hypot(1.5, 3.0), 2.0]])


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"noise_sd": np.ones(3)}, "noise_sd has shape"),
    ({"noise_sd": np.array([1.0, 0.0])}, "finite and positive"),
    ({"noise_sd": -np.ones((40, 2))}, "finite and positive"),
    ({"targets": ["m"]}, "unknown target 'm'"),
    ({"targets": [5]}, "unknown target 5"),
    ({"targets": ["a"], "theta": None}, "need theta"),
    ({"theta": np.zeros((39, 3))}, "theta has 39 rows"),
    ({"features": np.ones(40)}, "features must be a non-empty 2-D array"),
    ({"features": np.full((40, 2), np.nan)}, "features: row 0"),
    ({"features": np.ones((5, 2)), "theta": None}, "5 draws"),
    ({"n_outer": 3}, "n_outer = 3"),
])
def test_bad_input_is_one_line_naming_it(kwargs, message):
    rng = np.random.default_rng(0)
    args = {"features": rng.normal(size=(40, 2)), "noise_sd": np.ones(2), "theta": rng.normal(size=(40, 3)),
            "names": ["a", "b", "c"], "targets": None, **kwargs}
    with pytest.raises(InputError, match=message) as info:
        expected_information_gain(args.pop("features"), args.pop("noise_sd"), rng, **args)
    assert "\n" not in str(info.value)
