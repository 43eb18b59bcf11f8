"""The ensemble sampler on toys with known posteriors: a correlated Gaussian and two separated modes."""

from __future__ import annotations

import numpy as np

from shockcal.diagnostics import ess_bulk
from shockcal.sampler import run_ensemble


def test_linear_gaussian_posterior_mean_and_variance():
    # y = X theta + e, e ~ N(0, s^2 I), flat prior: posterior N((X'X)^-1 X'y, s^2 (X'X)^-1).
    rng = np.random.default_rng(1)
    x = rng.normal(size=(20, 3))
    y = x @ np.array([1.0, -2.0, 0.5]) + 0.3 * rng.normal(size=20)
    precision = x.T @ x / 0.3**2
    post_cov = np.linalg.inv(precision)
    post_mean = post_cov @ x.T @ y / 0.3**2

    def log_density(theta):
        r = y[None, :] - theta @ x.T
        return -0.5 * np.sum(r**2, axis=1) / 0.3**2

    init = post_mean + rng.normal(size=(32, 3))
    chains = run_ensemble(log_density, init, n_samples=40000, burn_in_steps=300, thin=1, mode_hop_fraction=0.1, seed=3)
    draws = chains.samples.reshape(-1, 3)
    sd = np.sqrt(np.diag(post_cov))
    for j in range(3):
        ess = ess_bulk(chains.samples[:, :, j])
        assert abs(draws[:, j].mean() - post_mean[j]) < 4 * sd[j] / np.sqrt(ess)
        # variance of a sample variance ~ 2 sd^4 / ESS
        assert abs(draws[:, j].var() / sd[j] ** 2 - 1) < 4 * np.sqrt(2 / ess)
    np.testing.assert_allclose(np.cov(draws.T), post_cov, rtol=0.1, atol=0.1 * sd.max() ** 2)


def test_two_modes_found_in_the_right_proportion():
    # Mixture 0.3 N(-3, 0.5) + 0.7 N(3, 0.5) in x, x2 ~ N(0,1): the barrier is ~18 nats deep.
    def log_density(theta):
        a = np.log(0.3) - 0.5 * ((theta[:, 0] + 3) / 0.5) ** 2
        b = np.log(0.7) - 0.5 * ((theta[:, 0] - 3) / 0.5) ** 2
        return np.logaddexp(a, b) - 0.5 * theta[:, 1] ** 2

    rng = np.random.default_rng(2)
    init = np.column_stack([rng.uniform(-6, 6, 32), rng.normal(size=32)])
    chains = run_ensemble(log_density, init, n_samples=40000, burn_in_steps=300, thin=1, mode_hop_fraction=0.2, seed=5)
    upper = chains.samples[:, :, 0] > 0
    share = upper.mean()
    per_walker = upper.mean(axis=1)
    assert abs(share - 0.7) < 0.04
    assert np.all((per_walker > 0.3) & (per_walker < 0.95)), "walkers must hop between modes, not stay put"


def test_stranded_walkers_restart_from_the_others():
    from shockcal.sampler import restart_lost_walkers

    coords = np.arange(20.0)[:, None] * np.ones((1, 2))
    log_prob = -np.linspace(0, 2, 20)
    log_prob[[3, 7]] = -80.0
    moved = restart_lost_walkers(coords, log_prob, np.random.default_rng(0))
    assert set(np.flatnonzero(np.any(moved != coords, axis=1))) == {3, 7}
    assert np.all(np.min(np.abs(moved[[3, 7], None, 0] - np.delete(coords, [3, 7], 0)[None, :, 0]), axis=1) < 0.1)
