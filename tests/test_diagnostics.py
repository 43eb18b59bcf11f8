"""Split R-hat and bulk/tail ESS on chains with known behaviour."""

from __future__ import annotations

import numpy as np

from shockcal.diagnostics import ess_bulk, ess_tail, split_rhat


def test_independent_draws_mix_and_have_full_ess():
    x = np.random.default_rng(0).normal(size=(4, 2000))
    assert split_rhat(x) < 1.01
    assert 0.8 * x.size < ess_bulk(x) < 1.2 * x.size
    assert 0.6 * x.size < ess_tail(x) < 1.4 * x.size


def test_autocorrelated_chain_has_ar1_ess():
    rng = np.random.default_rng(1)
    phi, n = 0.9, 20000
    x = np.empty((4, n))
    x[:, 0] = rng.normal(size=4)
    for t in range(1, n):
        x[:, t] = phi * x[:, t - 1] + np.sqrt(1 - phi**2) * rng.normal(size=4)
    expected = x.size * (1 - phi) / (1 + phi)
    assert 0.8 * expected < ess_bulk(x) < 1.25 * expected


def test_chains_stuck_apart_are_flagged():
    rng = np.random.default_rng(2)
    x = rng.normal(size=(4, 1000)) + np.array([0.0, 0.0, 3.0, 3.0])[:, None]
    assert split_rhat(x) > 1.05
    trend = rng.normal(size=(4, 1000)) + np.linspace(0, 3, 1000)   # non-stationary: split halves disagree
    assert split_rhat(trend) > 1.05
