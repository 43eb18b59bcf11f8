"""Verification of the hydrocode against closed-form solutions (thin plates keep these fast)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

from shockcal.hydro import ShotParameters, run_shot
from shockcal.hydro.laws.johnson_cook import JohnsonCook
from shockcal.hydro.plastic_return import NO_MEMORY, initial_hardening, plastic_return
from shockcal.hydro.state import LawStrength
from shockcal.hydro.strength import hardening, rate_factor, thermal_factor, thermal_factor_below
from shockcal.study.adapters import hydro_inputs

DATA = Path(__file__).parent / "data"

G = 0.27  # Mbar


def _setup(config, flyer_mm, target_mm, end_time_us, cell_size_um=4.0):
    config["hydro"].update(cell_size_um=cell_size_um, end_time_us=end_time_us)
    return {"flyer_mm": flyer_mm, "target_mm": target_mm}


def _hugoniot_shock_speed(config, up):
    """Shock speed (cm/us) of the Mie-Grueneisen cubic EOS at particle velocity up (cm/us)."""
    mat, eos = config["material"], config["material"]["eos"]
    rho0 = mat["rho0_g_cc"]

    def mismatch(mu):
        p_eos = eos["c1_Mbar"] * mu + eos["c2_Mbar"] * mu**2 + eos["c3_Mbar"] * mu**3 + eos["gamma0"] * rho0 * 0.5 * up**2
        return p_eos - rho0 * up**2 * (1.0 + mu) / mu

    mu = brentq(mismatch, 1e-6, 0.5)
    return up * (1.0 + mu) / mu


def _arrival(t, v, level):
    """First time the free-surface velocity crosses `level` (linear interpolation)."""
    k = int(np.argmax(v >= level))
    return t[k - 1] + (level - v[k - 1]) * (t[k] - t[k - 1]) / (v[k] - v[k - 1])


@pytest.mark.parametrize("velocity", [0.0204, 0.03549, 0.04838])
def test_no_strength_plateau_and_shock_speed(paper_config, velocity):
    params = ShotParameters.from_table_iv(0.0, 0.0, 0.0, 0.0, 0.0, velocity, G)
    arrivals = []
    for target_mm in (1.0, 2.0):
        shot = _setup(paper_config, 3.0, target_mm, 0.9)
        result = run_shot(params, *hydro_inputs(paper_config, shot))
        assert result.status == "ok", result.reason
        t, v = result.t_us, result.v_m_s
        arrivals.append(_arrival(t, v, 0.5 * velocity * 1e4))
    plateau = v[(t > arrivals[1] + 0.2) & (t < arrivals[1] + 0.5)].mean()   # after the ringing, before release
    assert plateau == pytest.approx(velocity * 1e4, rel=3e-3)
    shock_speed = 0.1 / (arrivals[1] - arrivals[0])
    assert shock_speed == pytest.approx(_hugoniot_shock_speed(paper_config, 0.5 * velocity), rel=1e-2)


def test_hugoniot_speeds_match_issue(paper_config):
    speeds = [_hugoniot_shock_speed(paper_config, 0.5 * v) * 1e4 for v in (0.0204, 0.03549, 0.04838)]
    assert speeds == pytest.approx([5528, 5621, 5701], abs=3)


def _elastic_reference(config, Y):
    rho0, K = config["material"]["rho0_g_cc"], config["material"]["eos"]["c1_Mbar"]
    modulus = K + 4.0 * G / 3.0
    c_long = math.sqrt(modulus / rho0)
    sigma_hel = modulus * Y / (2.0 * G)
    return 2.0 * sigma_hel / (rho0 * c_long) * 1e4, c_long


def _elastic_jump(config, Y):
    """The elastic precursor as a Rankine-Hugoniot jump of this EOS to the yield point (uniaxial strain,
    log strain Y / 2G, sigma_x = P + 2Y/3): (free-surface velocity m/s, wave speed cm/us). A finite
    elastic wave travels faster than c_L (0.59% for Y = 30 MPa, G = 0.27 Mbar), which the linear
    formula of `_elastic_reference` leaves out."""
    mat, eos = config["material"], config["material"]["eos"]
    rho0 = mat["rho0_g_cc"]
    mu = math.expm1(Y / (2.0 * G))
    compression = mu / (1.0 + mu)                     # 1 - rho0 / rho
    up = 0.0
    for _ in range(50):                                # fixed point on the tiny E = up^2 / 2 term
        pressure = eos["c1_Mbar"] * mu + eos["c2_Mbar"] * mu**2 + eos["c3_Mbar"] * mu**3 + eos["gamma0"] * rho0 * 0.5 * up**2
        stress = pressure + 2.0 * Y / 3.0
        speed = math.sqrt(stress / (rho0 * compression))
        up = stress / (rho0 * speed)
    return 2.0 * up * 1e4, speed


def _precursor(config, cell_size_um, target_mm, Y=0.003, C=0.0):
    """Constant yield Y (B = 0, no thermal softening; rate term C): (precursor amplitude m/s, half-level arrival us)."""
    config["material"]["T_melt_K"] = 1.0e12           # T* ~ 1e-10: no thermal softening
    _, c_long = _elastic_reference(config, Y)
    t_elastic = target_mm * 0.1 / c_long
    shot = _setup(config, 2.0, target_mm, t_elastic + 0.05, cell_size_um)
    result = run_shot(ShotParameters.from_table_iv(Y, 0.0, C, 0.0, 1.0, 0.0204, G), *hydro_inputs(config, shot))
    assert result.status == "ok", result.reason
    t, v = result.t_us, result.v_m_s
    amplitude = np.median(v[(t > t_elastic + 0.02) & (t < t_elastic + 0.045)])
    return amplitude, _arrival(t, v, 0.5 * amplitude)


def test_constant_yield_precursor_amplitude(paper_config):
    amplitude, _ = _precursor(paper_config, 4.0, 6.0)
    assert amplitude == pytest.approx(_elastic_reference(paper_config, 0.003)[0], rel=2e-2)   # linear formula
    assert amplitude == pytest.approx(_elastic_jump(paper_config, 0.003)[0], rel=2e-3)        # finite jump


def test_constant_yield_precursor_arrival(paper_config):
    """Half-level arrival against thickness / c_L (linear, 0.5%) and against the jump speed (0.2%)."""
    _, arrival = _precursor(paper_config, 4.0, 6.0)
    c_long = _elastic_reference(paper_config, 0.003)[1]
    speed = _elastic_jump(paper_config, 0.003)[1]
    assert arrival == pytest.approx(0.6 / c_long, rel=1e-2)
    assert arrival == pytest.approx(0.6 / speed, rel=2e-3)


def test_mesh_convergence(paper_config):
    """Precursor amplitude and plateau at 8, 4, 2 um agree with the analytic values and converge."""
    amplitudes = [_precursor(paper_config, dx, 2.0)[0] for dx in (8.0, 4.0, 2.0)]
    u_ref = _elastic_jump(paper_config, 0.003)[0]
    errors = [abs(a - u_ref) / u_ref for a in amplitudes]
    assert max(errors) < 2e-2
    assert errors[2] <= errors[0] + 2e-3


def test_energy_conserved(paper_config):
    shot = _setup(paper_config, 1.0, 1.5, 0.5)
    result = run_shot(ShotParameters.from_table_iv(0.0017, 0.00425, 0.0335, 0.42, 1.225, 0.0204, G), *hydro_inputs(paper_config, shot))
    assert result.status == "ok", result.reason
    assert result.energy_error < 1e-3


def test_numerical_failure_is_reported(paper_config):
    shot = _setup(paper_config, 0.5, 0.5, 0.2)
    geometry, material, settings = hydro_inputs(paper_config, shot)
    object.__setattr__(settings, "cfl", 3.0)   # unstable on purpose, past the check that refuses it (test_hydro_rules)
    result = run_shot(ShotParameters.from_table_iv(0.001, 0.0, 0.0, 0.0, 1.0, 0.0204, G), geometry, material, settings)
    assert result.status == "failed"
    assert "cell" in result.reason and "t =" in result.reason


def test_strength_conventions():
    assert hardening(0.001, 0.002, 0.0, 0.0) == pytest.approx(0.003)     # n = 0: eps^0 = 1
    assert hardening(0.001, 0.002, 0.5, 0.0) == 0.001
    assert rate_factor(0.03, 0.5e-6, 1e-6) == 1.0                         # ratio floored at 1
    assert rate_factor(0.03, math.e * 1e-6, 1e-6) == pytest.approx(1.03)
    assert thermal_factor(1.2, -0.1) == 1.0                               # T* <= 0: no softening
    assert thermal_factor(0.0, 0.1) == 0.0                                # m = 0 limit, T* > 0
    assert thermal_factor(0.0, 0.0) == 1.0
    assert thermal_factor(2.0, 0.5) == pytest.approx(0.75)
    rate_free = LawStrength(JohnsonCook(0.003, 0.0, 0.0, 0.0, 1.0, 298.0, 893.0, 1e-6), G)   # Y = 0.003 Mbar
    cell = (298.0, 1e-3, 0.0, 1.0, G, 0.0, initial_hardening(rate_free), 0.0, 0.0, math.inf, rate_free, None,
            NO_MEMORY)
    s, d_eps = plastic_return(-0.004, *cell)[:2]                          # 1.5 * 0.004 = 0.006 > 0.003
    assert 1.5 * abs(s) == pytest.approx(0.003) and s < 0
    assert d_eps == pytest.approx(0.003 / (3 * G))
    assert plastic_return(0.001, *cell)[:2] == (0.001, 0.0)


@pytest.mark.parametrize("path, value", [(("shots", "104S", "flyer_mm"), 0.0), (("shots", "105S", "target_mm"), -1.0),
                                         (("hydro", "cell_size_um"), 0.0)])
def test_non_positive_geometry_is_a_config_error(paper_config, path, value):
    from shockcal.errors import ConfigError
    from shockcal.study.validate import validate_config

    node = paper_config
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value
    with pytest.raises(ConfigError, match=path[-1]):
        validate_config(paper_config)


def test_c0_traces_identical_to_the_lagged_rate_code(paper_config):
    """C = 0 makes the rate convention irrelevant: traces stored before the rate change are reproduced (the
    code before and today's are two paths: at the rounding floor, rtol 1e-10 of the peak)."""
    stored = np.load(DATA / "c0_traces_before_rate_change.npz")
    cases = {"gray_c0_104": ShotParameters.from_table_iv(0.0017, 0.00425, 0.0, 0.42, 1.225, 0.0204, 0.27),
             "hard_c0_106": ShotParameters.from_table_iv(0.004, 0.002, 0.0, 0.2, 0.8, 0.04838, 0.33)}
    shot = _setup(paper_config, 1.0, 1.5, 0.6)
    for name, params in cases.items():
        result = run_shot(params, *hydro_inputs(paper_config, shot))
        np.testing.assert_allclose(result.v_m_s, stored[name], rtol=1e-10, atol=1e-10 * np.max(np.abs(stored[name])), err_msg=name)


# Johnson-Cook cases whose traces tests/data/make_floor_free_traces.py stores from the code without the floor
# skips (rate term on, small m, n = 0, strong and hot cases): Table IV units, the 1.0 / 1.5 mm plates to 0.6 us.
JC_FLOOR_CASES = {"gray_104": (0.0017, 0.00425, 0.0335, 0.42, 1.225, 0.0204, 0.27),
                  "soft_m_106": (0.0032, 0.004, 0.0046, 0.69, 0.01, 0.04838, 0.30),
                  "n0_105": (0.0072, 0.003, 0.0159, 0.0, 1.10, 0.03549, 0.28),
                  "rate_hot_106": (0.0045, 0.008, 0.0248, 0.62, 2.47, 0.04838, 0.33),
                  "strong_104": (0.0097, 0.002, 0.0267, 1.06, 2.85, 0.0204, 0.26)}


def test_flow_stress_floors_change_no_trace(paper_config):
    """The kernel skips the flow stress where a cell's trial stress lies inside a lower bound of it (the
    flow-stress floors, 2026-11-24): traces stored from the same code with the floor skips removed
    (tests/data/make_floor_free_traces.py, regenerated 2026-11-29 when the rate term moved inside the return)
    are reproduced at the rounding floor (rtol 1e-10 of the peak: the two are two paths)."""
    stored = np.load(DATA / "traces_without_flow_floors.npz")
    assert set(stored.files) == set(JC_FLOOR_CASES)
    shot = _setup(paper_config, 1.0, 1.5, 0.6)
    for name, table_iv in JC_FLOOR_CASES.items():
        np.testing.assert_allclose(run_shot(ShotParameters.from_table_iv(*table_iv), *hydro_inputs(paper_config, shot)).v_m_s,
                                   stored[name], rtol=1e-10, atol=1e-10 * np.max(np.abs(stored[name])), err_msg=name)


def test_thermal_factor_bound_lies_below_the_factor():
    """thermal_factor_below(m, T*, thermal_factor(m, T*), dT*) <= thermal_factor(m, T* + dT*) for every
    m of the box and beyond, T* from cold to near melt, and margins of 0.1-10 K (T_melt - T_ref = 600 K)."""
    worst_gap = np.inf
    for m in [0.0, 0.01, 0.05, 0.3, 1.0, 1.7, 3.0, 6.0]:
        for T in np.geomspace(1e-6, 0.99, 60):
            for dT in [0.1 / 600, 1.0 / 600, 10.0 / 600]:
                bound = thermal_factor_below(m, T, thermal_factor(m, T), dT)
                exact = thermal_factor(m, T + dT)
                assert 0.0 <= bound <= exact, (m, T, dT, bound, exact)
                worst_gap = min(worst_gap, exact - bound)
    assert worst_gap >= 0.0
    assert thermal_factor_below(1.2, 0.0, 1.0, 0.01) == 0.0              # cold cell: no bound


@pytest.mark.parametrize("cell_size_um", [8.0, 4.0, 2.0])
def test_precursor_carries_the_rate_term(paper_config, cell_size_um):
    """The elastic precursor is set at the front's strain rate (about 1e6-1e7 /s here), so it rises with C:
    (amplitude(C) / amplitude(0) - 1) / C is ln of that rate, 13.1-15.1 at 2-8 um (docs/hydro.md). A rate
    term lagged by a step would leave the plateau at the C = 0 value."""
    base, _ = _precursor(paper_config, cell_size_um, 2.0)
    for C in (0.01, 0.03):
        amplitude, _ = _precursor(paper_config, cell_size_um, 2.0, C=C)
        assert 13.0 < (amplitude / base - 1.0) / C < 18.0
