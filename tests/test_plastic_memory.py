"""What a cell that stays plastic reuses (`hydro/series.py`, Johnson-Cook's memory kernels): each the value the
plain evaluation gives, to rounding."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shockcal.hydro.laws.johnson_cook import (
    JohnsonCook,
    johnson_cook_flow_stress,
    johnson_cook_hardening,
    johnson_cook_hardening_after,
    johnson_cook_plastic_increment,
    johnson_cook_plastic_increment_warm,
    johnson_cook_rate_free_flow_stress,
)
from shockcal.hydro.series import EXP_STEP_MAX, NO_SERIES, exp_small, power_growth

JC = JohnsonCook(0.0017, 0.00425, 0.0335, 0.42, 1.225, 298.0, 893.0, 1e-6)   # Mbar, -, K, 1/us
ROUNDING = 4e-16


@pytest.mark.parametrize("s", [-EXP_STEP_MAX, -3e-3, -1e-7, 0.0, 2e-9, 4e-4, EXP_STEP_MAX])
def test_exp_small_is_the_exponential(s):
    assert exp_small(s) == pytest.approx(math.exp(s), rel=ROUNDING, abs=0.0)


@pytest.mark.parametrize("m", [0.01, 0.42, 1.225, 2.85, 7.5])
@pytest.mark.parametrize("u", [-2e-3, -1e-5, 3e-8, 1e-4, 1e-3])
def test_power_growth_is_the_power_or_refuses(m, u):
    growth = power_growth(u, m)
    if growth == NO_SERIES:                                         # only where its first omitted term is large
        c6 = math.prod(m - k for k in range(6)) / math.factorial(6)
        assert abs(c6) * u**6 > 1e-17
    else:
        assert growth == pytest.approx(math.expm1(m * math.log1p(u)), rel=ROUNDING, abs=1e-17)   # no rounding of 1 + u
    assert power_growth(0.05, 1.225) == NO_SERIES                   # far too large a change: the pow


def test_hardening_after_a_small_increment_is_the_hardening():
    eps_p, hard = 0.013, johnson_cook_hardening(JC, 0.013)
    for d_eps in (1e-9, 4e-6, 1e-4, 0.02, 0.5):
        assert johnson_cook_hardening_after(JC, hard, eps_p, d_eps) == pytest.approx(
            johnson_cook_hardening(JC, eps_p + d_eps), rel=ROUNDING, abs=0.0)
    assert johnson_cook_hardening_after(JC, JC.A, 0.0, 1e-6) == johnson_cook_hardening(JC, 1e-6)   # first yield: the pow


def test_rate_free_flow_stress_from_the_remembered_power():
    hard, power_T = johnson_cook_hardening(JC, 0.02), 412.0
    power = ((power_T - JC.T_ref) / (JC.T_melt - JC.T_ref)) ** JC.m
    for T in (412.0, 412.003, 412.4, 430.0, 290.0):
        Y0, T_new, power_new = johnson_cook_rate_free_flow_stress(JC, hard, T, power_T, power)
        assert Y0 == pytest.approx(johnson_cook_flow_stress(JC, 0.02, 0.0, T, 0.0, 1.0), rel=ROUNDING, abs=0.0)
        if T > JC.T_ref:
            assert T_new == T and power_new == pytest.approx(((T - JC.T_ref) / (JC.T_melt - JC.T_ref)) ** JC.m,
                                                             rel=ROUNDING)
    rate_free_law = JC._replace(C=0.0)                              # no rate term: the pow, bit for bit
    Y0 = johnson_cook_rate_free_flow_stress(rate_free_law, hard, 412.4, power_T, power)[0]
    assert Y0 == johnson_cook_flow_stress(rate_free_law, 0.02, 0.0, 412.4, 0.0, 1.0)


@pytest.mark.parametrize("warm_error", [0.0, 1e-6, -3e-4, 4e-3, -0.2, 3.0])
def test_a_warm_start_gives_the_cold_solution(warm_error):
    """From the cell's last plastic rate, near the root or far from it (then the upper bound), the increment and
    flow stress are the cold solve's to rounding, and the memory is the solution's x and rate."""
    G, dt, T = 0.27, 4e-4, 330.0
    hard = johnson_cook_hardening(JC, 0.01)
    rate_free = johnson_cook_flow_stress(JC, 0.01, 0.0, T, 0.0, 1.0)
    for overstress in (1e-6, 3e-5, 2e-4):
        equivalent = rate_free + overstress
        d, Y = johnson_cook_plastic_increment(JC, equivalent, rate_free, G, dt, hard, 0.01, T, 0.0, 1.0)
        x = math.log(d / (dt * JC.rate_ref)) + warm_error
        d_warm, Y_warm, x_new, rate_new = johnson_cook_plastic_increment_warm(
            JC, equivalent, rate_free, G, dt, hard, 0.01, T, 0.0, 1.0, x, JC.rate_ref * math.exp(x))
        assert d_warm == pytest.approx(d, rel=1e-14) and Y_warm == pytest.approx(Y, rel=1e-15)
        assert rate_new == pytest.approx(d / dt, rel=1e-14)
        assert np.exp(x_new) * JC.rate_ref == pytest.approx(rate_new, rel=1e-13)
