"""The evidence with the prior box halved and doubled, from one run's weighted draws (shockcal.campaign.box_sensitivity),
against closed forms: a Gaussian likelihood in a 2-D box (Z of any sub-box from the normal CDF), and a
likelihood that vanishes outside the box."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate, special, stats

from shockcal.campaign.box_sensitivity import (
    box_sensitivity,
    double_box_log_z,
    doubled_box,
    half_box,
    mass_near_moved_faces,
    physical_floor,
)
from shockcal.inference.sampler import WeightedDraws

LOWER, UPPER = np.array([1.0, 0.0]), np.array([3.0, 2.0])        # box volume 4; centre (2, 1)
MU, SD = np.array([2.1, 0.9]), 0.3                                  # a normalised Gaussian likelihood


def gaussian_log_z(lower, upper) -> float:
    """log of the uniform prior on [lower, upper] times the Gaussian likelihood, integrated (exact)."""
    mass = np.prod(stats.norm.cdf((upper - MU) / SD) - stats.norm.cdf((lower - MU) / SD))
    return float(math.log(mass) - np.sum(np.log(upper - lower)))


def importance_draws(n: int, seed: int, log_z: float) -> WeightedDraws:
    """Draws from the prior weighted by the likelihood (self-normalised importance sampling), with the exact
    log Z and sd 0, so only the posterior mass's Monte Carlo error is left."""
    rng = np.random.default_rng(seed)
    points = LOWER + (UPPER - LOWER) * rng.uniform(size=(n, 2))
    log_l = stats.norm.logpdf(points, MU, SD).sum(axis=1)
    return WeightedDraws(points, log_l - special.logsumexp(log_l), log_l, log_z, n, 0.0)


def test_half_box_equals_the_half_boxs_own_evidence_within_its_sd():
    log_z = gaussian_log_z(LOWER, UPPER)
    exact = gaussian_log_z(LOWER + 0.25 * (UPPER - LOWER), UPPER - 0.25 * (UPPER - LOWER))
    estimate, sd, mass = half_box(importance_draws(20000, 1, log_z), LOWER, UPPER)
    assert 0.5 < mass < 1.0
    assert 0 < sd < 0.05
    assert abs(estimate - exact) < 3 * sd


def test_half_box_sd_matches_the_spread_over_seeds():
    log_z = gaussian_log_z(LOWER, UPPER)
    runs = [half_box(importance_draws(400, seed, log_z), LOWER, UPPER) for seed in range(300)]
    spread = np.std([r[0] for r in runs])
    assert np.median([r[1] for r in runs]) == pytest.approx(spread, rel=0.2)


def test_half_box_adds_log_z_sd_in_quadrature_and_warns_when_empty(caplog):
    points = np.array([[1.1, 0.1], [2.9, 1.9]])                      # both outside the half box
    draws = WeightedDraws(points, np.log([0.5, 0.5]), np.zeros(2), -10.0, 2, 0.1)
    assert half_box(draws, LOWER, UPPER, "ptw")[:2] == (-math.inf, pytest.approx(math.nan, nan_ok=True))
    assert "ptw: no posterior draw inside the half box" in caplog.text and "Kish ESS 2" in caplog.text
    inside = WeightedDraws(np.array([[2.0, 1.0], [2.9, 1.9]]), np.log([0.5, 0.5]), np.zeros(2), -10.0, 2, 0.1)
    log_z_half, sd, mass = half_box(inside, LOWER, UPPER)
    assert mass == 0.5 and log_z_half == pytest.approx(-10.0 + 2 * math.log(2) + math.log(0.5))
    assert sd == pytest.approx(math.hypot(0.1, math.sqrt(0.25 / 2) / 0.5))            # equal weights: binomial


def bump(x, lower, upper):
    """A likelihood that integrates to the box volume over [lower, upper] and is zero outside it."""
    u = (np.asarray(x) - lower) / (upper - lower)
    inside = np.all((u >= 0) & (u <= 1), axis=-1)
    return np.where(inside, np.prod(30 * u**2 * (1 - u) ** 2, axis=-1), 0.0)


def test_double_box_is_exact_when_the_likelihood_vanishes_outside_the_box():
    floor = physical_floor(LOWER)                                     # both lows >= 0: floors at 0
    low2, high2 = doubled_box(LOWER, UPPER, floor)
    np.testing.assert_allclose(low2, [0.0, 0.0])                      # 1 - 1 = 0; 0 - 1 clipped at 0
    np.testing.assert_allclose(high2, [4.0, 3.0])
    volume = np.prod(high2 - low2)
    integral, _ = integrate.dblquad(lambda y, x: bump([x, y], LOWER, UPPER), low2[0], high2[0], low2[1], high2[1],
                                    epsabs=1e-12)
    log_z = math.log(4.0 / 4.0)                                       # the bump integrates to 4 over a box of volume 4
    assert double_box_log_z(log_z, LOWER, UPPER, floor) == pytest.approx(math.log(integral / volume), abs=1e-8)


def test_double_box_without_floor_and_as_a_lower_bound():
    lower, upper = np.array([-1.0]), np.array([1.0])                  # reaches below 0: no floor
    assert physical_floor(lower)[0] == -np.inf
    assert double_box_log_z(0.0, lower, upper, physical_floor(lower)) == pytest.approx(-math.log(2))
    log_z = gaussian_log_z(LOWER, UPPER)
    low2, high2 = doubled_box(LOWER, UPPER, physical_floor(LOWER))
    bound = double_box_log_z(log_z, LOWER, UPPER, physical_floor(LOWER))
    assert bound < gaussian_log_z(low2, high2) < bound + 0.1         # the likelihood outside adds a little


def test_mass_near_the_faces_the_doubled_box_moves():
    lower, upper = np.array([0.0, 1.0]), np.array([1.0, 2.0])        # x's low face sits at its floor 0
    points = np.array([[0.01, 1.5],          # near x's low face: the doubled box does not move it
                       [0.5, 1.02],          # near y's low face (1 -> 0.5): counted
                       [0.97, 1.5],          # near x's high face: counted
                       [0.5, 1.5]])
    draws = WeightedDraws(points, np.log([0.1, 0.2, 0.3, 0.4]), np.zeros(4), 0.0, 4)
    assert mass_near_moved_faces(draws, lower, upper, physical_floor(lower)) == pytest.approx(0.5)
    result = box_sensitivity(draws, lower, upper)
    assert result.k == 2 and result.mass_near_faces == pytest.approx(0.5)
