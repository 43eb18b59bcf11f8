"""Verification of the strength-law kernels (shockcal.hydro.laws) before any calibration uses them.

1. Johnson-Cook equals today's hydrocode flow stress (hydro.strength, T* in the hydrocode's order)
   bit for bit.
2. Every law against its closed form at constant rate and temperature, written here in plain numpy in
   user/SI units from the papers (not from the kernels), over a grid of strain, rate, temperature,
   pressure and density ratio: relative error <= 1e-10. This also checks the declared unit conversions.
3. Second, independent checks: PTW's integrated hardening against a numerical integration of its
   differential law (PTW 2003 eq. (5)); Steinberg-Guinan's G and melt law against their defining
   derivatives (G'_P, G'_T, Lindemann). With LANL's impala installed (optional, `pip install
   impala-calib`), PTW and SG also against impala's implementation; skipped with a message otherwise.
4. The parameter declarations, config/models.yaml and `shockcal flow-stress`.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from scipy.constants import Avogadro
from scipy.integrate import solve_ivp
from scipy.special import erf

from shockcal.cli import main
from shockcal.errors import InputError
from shockcal.hydro.laws import LAWS, code_parameters, flow_stress_curve, get_law, shear_modulus_gpa
from shockcal.hydro.laws.boxes import load_boxes
from shockcal.hydro.laws.johnson_cook import JohnsonCook, johnson_cook_flow_stress
from shockcal.hydro.laws.kernels import (
    law_flow_stress_at,
    law_flow_stress_floor,
    law_hardening,
    law_shear_modulus,
)
from shockcal.hydro.laws.steinberg_guinan import (
    steinberg_guinan_melt_temperature,
    steinberg_guinan_melt_temperature_below,
    steinberg_guinan_shear_modulus,
)
from shockcal.hydro.material_library import load_material
from shockcal.hydro.plastic_return import LAW_FLOOR_SLACK
from shockcal.hydro.state import Material
from shockcal.hydro.strength import hardening, rate_factor, thermal_factor
from shockcal.units import PER_S_TO_PER_US

RTOL = 1e-10
STRAINS = np.array([0.0, 1e-4, 0.003, 0.02, 0.05, 0.1, 0.2, 0.5])

# ---------------------------------------------------------------------------------------------- parameter sets
JC_SETS = [
    dict(A_MPa=270, B_MPa=470, C=0.0105, n=0.6, m=1.2),                 # Gray et al., SPEC section 3
    dict(A_MPa=170, B_MPa=425, C=0.0335, n=0.42, m=1.225),
    dict(A_MPa=50, B_MPa=1000, C=0.03, n=0.0, m=0.0),                   # the n = 0 and m = 0 conventions
    dict(A_MPa=1000, B_MPa=50, C=0.0, n=1.5, m=3.0),
]
SG_SETS = [
    dict(Y0_GPa=0.29, Ymax_GPa=0.68, beta=125, n=0.1, G0_GPa=27.6, dGdP=1.8, dGdT_over_G0_per_K=-6.16e-4),  # 6061-T6
    dict(Y0_GPa=0.26, Ymax_GPa=0.76, beta=310, n=0.185, G0_GPa=28.6, dGdP=1.86, dGdT_over_G0_per_K=-6.16e-4,
         gamma0=2.0),                                                                                         # 2024-T4
    dict(Y0_GPa=0.4, Ymax_GPa=0.45, beta=20, n=0.3, eps_i=0.01, G0_GPa=35.0, dGdP=2.5, dGdT_over_G0_per_K=-9e-4,
         T_m0_K=1100.0, gamma0=1.8, a=1.2),                                                                   # capped
]
AL5083 = load_material("al5083")   # the material constants the laws read (molar mass, melt law) when not given
AL = dict(M_g_per_mol=26.9815, rho0_g_per_cc=2.668, G0_GPa=28.0, alpha=0.23, T_melt_K=893.0)
PTW_SETS = [
    dict(theta=0.025, p=2.0, s0=0.0085, sinf=0.00055, kappa=0.11, gamma=1e-5, y0=0.0001, yinf=0.00009999,
         y1=0.094, y2=0.575, beta=0.25, **AL),                     # impala's OFHC Cu test values on Al constants
    dict(theta=0.02, p=0.0, s0=0.012, sinf=0.00325, kappa=0.6, gamma=4e-5, y0=0.01, yinf=0.00125,
         y1=0.013, y2=0.4, beta=0.23, **AL),                       # PTW 2003 Ta values (p = 0 branch)
    dict(theta=0.128, p=3.03, s0=0.0259, sinf=0.0219, kappa=0.159, gamma=3.78e-5, y0=0.0237, yinf=0.0054,
         y1=0.09, y2=0.4, beta=0.33, **AL),                        # impala's Ti-6Al-4V example values
    dict(theta=0.05, p=0.5, s0=0.006, sinf=0.002, kappa=0.3, gamma=1e-7, y0=0.004, yinf=0.001,
         y1=0.02, y2=0.5, beta=0.3, **AL),                         # small gamma: overdriven branches at high rate
]
ZA_SETS = [
    dict(C0_MPa=65, C2_MPa=890, C3_per_K=0.0028, C4_per_K=0.000115),   # ZA 1987 copper magnitudes
    dict(C0_MPa=250, C2_MPa=400, C3_per_K=0.001, C4_per_K=0.00005),
    dict(C0_MPa=100, C2_MPa=1500, C3_per_K=0.005, C4_per_K=0.0003, rate_ref_per_s=1e-3),
]

RATES = [1e-3, 1.0, 1e3, 1e5, 1e6, 1e7]                  # 1/s
TEMPERATURES = [77.0, 298.0, 450.0, 700.0, 880.0]        # K
PRESSURES = [-1.0, 0.0, 2.0, 5.0, 12.0]                  # GPa
DENSITY_RATIOS = [0.98, 1.0, 1.03, 1.1]


# ---------------------------------------------------------------------------------------------- closed forms
def jc_closed(v, eps, rate, T):
    """Johnson-Cook (1983) with the SPEC's conventions, MPa."""
    v = {"T_ref_K": 298.0, "T_melt_K": 893.0, "rate_ref_per_s": 1.0} | v
    power = np.ones_like(eps) if v["n"] == 0 else eps ** v["n"]
    rate_term = 1.0 + v["C"] * np.log(max(rate / v["rate_ref_per_s"], 1.0))
    t_star = (T - v["T_ref_K"]) / (v["T_melt_K"] - v["T_ref_K"])
    softening = 1.0 if t_star <= 0 else (0.0 if (t_star >= 1 or v["m"] == 0) else 1.0 - t_star ** v["m"])
    return (v["A_MPa"] + v["B_MPa"] * power) * rate_term * softening


def sg_melt(v, eta):
    v = {"T_m0_K": 1220.0, "gamma0": 1.97, "a": 1.5} | v
    return v["T_m0_K"] * np.exp(2 * v["a"] * (1 - 1 / eta)) * eta ** (2 * (v["gamma0"] - v["a"] - 1 / 3))


def sg_shear(v, P, T, eta):
    """Steinberg-Cochran-Guinan (1980) G(P, T), GPa."""
    G = v["G0_GPa"] + v["dGdP"] * P / np.cbrt(eta) + v["G0_GPa"] * v["dGdT_over_G0_per_K"] * (T - 300.0)
    return 0.0 if T >= sg_melt(v, eta) else max(G, 0.0)


def sg_closed(v, eps, P, T, eta):
    """Steinberg-Guinan (1980) flow stress, MPa."""
    eps_i = v.get("eps_i", 0.0)
    hardened = np.minimum(v["Y0_GPa"] * (1 + v["beta"] * (eps + eps_i)) ** v["n"], v["Ymax_GPa"])
    return 1e3 * hardened * sg_shear(v, P, T, eta) / v["G0_GPa"]


def ptw_rate_scale_si(v, T, eta):
    """PTW's xi_dot in 1/s, from SI quantities: 1/2 (4 pi rho N_A / 3 M)^(1/3) sqrt(G / rho)."""
    rho = v["rho0_g_per_cc"] * 1e3 * eta                    # kg/m^3
    molar = v["M_g_per_mol"] * 1e-3                          # kg/mol
    G = v["G0_GPa"] * 1e9 * (1 - v["alpha"] * T / v["T_melt_K"])   # Pa
    return 0.5 * (4 * math.pi * rho * Avogadro / (3 * molar)) ** (1 / 3) * math.sqrt(G / rho)


def ptw_stresses(v, rate, T, eta):
    """(tau_s, tau_y) over G of PTW 2003 eqs. (7)-(8) (their saturation and yield stresses)."""
    r = rate / (v["gamma"] * ptw_rate_scale_si(v, T, eta))
    e = erf(v["kappa"] * (T / v["T_melt_K"]) * np.log(1 / r))
    tau_s = max(v["s0"] - (v["s0"] - v["sinf"]) * e, v["s0"] * r ** v["beta"])
    tau_y = max(v["y0"] - (v["y0"] - v["yinf"]) * e, min(v["y1"] * r ** v["y2"], v["s0"] * r ** v["beta"]))
    return tau_s, tau_y


def ptw_closed(v, eps, rate, T, eta):
    """PTW 2003 flow stress 2 G tau (MPa) with the integrated hardening law, eq. (6)."""
    tau_s, tau_y = ptw_stresses(v, rate, T, eta)
    s0, p, theta = v["s0"], v["p"], v["theta"]
    if tau_s <= tau_y:                                   # no room to harden (overdriven: both s0 r^beta)
        tau = tau_s + 0 * eps
    elif p == 0:
        tau = tau_s - (tau_s - tau_y) * np.exp(-theta * eps / (tau_s - tau_y))
    else:
        x = p * (tau_s - tau_y) / (s0 - tau_y)
        tau = tau_s + (s0 - tau_y) / p * np.log(
            1 - (1 - np.exp(-x)) * np.exp(-p * theta * eps / ((s0 - tau_y) * (np.exp(x) - 1))))
    G_MPa = 1e3 * v["G0_GPa"] * (1 - v["alpha"] * T / v["T_melt_K"])
    return 2 * G_MPa * tau


def za_closed(v, eps, rate, T):
    """Zerilli-Armstrong fcc (1987), MPa."""
    ref = v.get("rate_ref_per_s", 1.0)
    exponent = -v["C3_per_K"] * T + v["C4_per_K"] * T * np.log(rate / ref)
    return v["C0_MPa"] + v["C2_MPa"] * np.sqrt(eps) * np.exp(exponent)


def relative_error(got, want) -> float:
    got, want = np.asarray(got, float), np.asarray(want, float)
    assert np.all(np.isfinite(got)) and np.all(np.isfinite(want))
    scale = np.abs(want)
    err = np.where(scale > 0, np.abs(got - want) / np.where(scale > 0, scale, 1.0), np.abs(got))
    return float(err.max())


def grid_error(law_name, sets, closed, states) -> float:
    law = get_law(law_name)
    worst = 0.0
    states = list(states)
    for values in sets:
        for rate, T, P, eta in states:
            got = flow_stress_curve(law, values, STRAINS, rate, T, P, eta, material=AL5083)
            worst = max(worst, relative_error(got, closed(values, STRAINS, rate, T, P, eta)))
    return worst


# ---------------------------------------------------------------------------------------------- 1. JC bit for bit
def test_johnson_cook_is_the_product_of_its_factors_bit_for_bit():
    material = Material(rho0=2.668, c1=0.7797, c2=0.2239, c3=1.668, gamma0=2.13, T_ref=298.0, T_melt=893.0, cv=9e-6)
    rates = [0.0, 1e-9, 1e-7, 1e-6, 1.5e-6, 1e-3, 0.7, 1.75, 12.0]             # plastic rates, 1/us
    for A, B, C, n, m in [(0.0027, 0.0047, 0.0105, 0.6, 1.2), (0.0005, 0.01, 0.03, 0.0, 0.0),
                          (0.01, 0.0005, 0.0, 1.5, 3.0), (0.002, 0.006, 0.02, 0.3, 0.05)]:
        law = JohnsonCook(A, B, C, n, m, material.T_ref, material.T_melt, 1e-6)
        for eps, rate, T in itertools.product(STRAINS, rates, [250.0, 298.0, 298.5, 309.0, 365.0, 892.9, 893.0, 1200.0]):
            homologous = (T - material.T_ref) * (1.0 / (material.T_melt - material.T_ref))
            product = hardening(A, B, n, eps) * rate_factor(C, rate, 1e-6) * thermal_factor(m, homologous)
            assert johnson_cook_flow_stress(law, eps, rate, T, 0.0, 1.0) == product, (A, B, C, n, m, eps, rate, T)


# ---------------------------------------------------------------------------------------------- 2. closed forms
def test_johnson_cook_against_its_closed_form():
    states = itertools.product(RATES, [250.0, 298.0, 450.0, 700.0, 880.0, 900.0], [0.0], [1.0])
    error = grid_error("johnson-cook", JC_SETS, lambda v, e, rate, T, P, eta: jc_closed(v, e, rate, T), states)
    assert error <= RTOL


def test_steinberg_guinan_against_its_closed_form():
    states = itertools.product([1.0], TEMPERATURES + [1150.0, 1300.0], PRESSURES, DENSITY_RATIOS)
    error = grid_error("steinberg-guinan", SG_SETS, lambda v, e, rate, T, P, eta: sg_closed(v, e, P, T, eta), states)
    assert error <= RTOL


def test_steinberg_guinan_shear_modulus_against_its_closed_form():
    law = get_law("sg")
    worst = 0.0
    for values in SG_SETS:
        for T, P, eta in itertools.product(TEMPERATURES + [1150.0, 1300.0], PRESSURES, DENSITY_RATIOS):
            worst = max(worst, relative_error(shear_modulus_gpa(law, values, T, P, eta, material=AL5083), sg_shear(values, P, T, eta)))
    assert worst <= RTOL


def test_ptw_against_its_closed_form():
    states = itertools.product(RATES, TEMPERATURES, [0.0], DENSITY_RATIOS)
    error = grid_error("ptw", PTW_SETS, lambda v, e, rate, T, P, eta: ptw_closed(v, e, rate, T, eta), states)
    assert error <= RTOL


def test_zerilli_armstrong_against_its_closed_form():
    states = itertools.product(RATES, TEMPERATURES, [0.0], [1.0])
    error = grid_error("zerilli-armstrong", ZA_SETS, lambda v, e, rate, T, P, eta: za_closed(v, e, rate, T), states)
    assert error <= RTOL


def test_conventions_at_the_edges():
    """Zero rate, zero temperature and melt: finite, and the documented limits."""
    ptw = get_law("ptw")
    values = PTW_SETS[0]
    quasi_static = flow_stress_curve(ptw, values, STRAINS, 0.0, 298.0, material=AL5083)
    slow = flow_stress_curve(ptw, values, STRAINS, 1e-290, 298.0, material=AL5083)   # erf(kappa T^ ln(1/r)) = 1
    assert np.allclose(quasi_static, slow, rtol=1e-6) and np.all(quasi_static > 0)
    assert np.all(np.isfinite(flow_stress_curve(ptw, values, STRAINS, 1e3, 0.0, material=AL5083)))
    assert np.all(flow_stress_curve(ptw, values, STRAINS, 1e3, 893.0, material=AL5083) == 0.0)
    za = ZA_SETS[0]
    assert np.allclose(flow_stress_curve(get_law("za"), za, STRAINS, 0.0, 298.0, material=AL5083), za["C0_MPa"], rtol=1e-14, atol=0)
    assert np.all(flow_stress_curve(get_law("sg"), SG_SETS[0], STRAINS, 1.0, 1220.0, material=AL5083) == 0.0)


# ---------------------------------------------------------------------------------------------- 3. second checks
@pytest.mark.parametrize("values", PTW_SETS, ids=["cu-like", "ta-p0", "ti64-like", "overdriven"])
def test_ptw_hardening_integrates_its_differential_law(values):
    """d tau/d psi = theta (exp(p (tau_s - tau)/(s0 - tau_y)) - 1) / (exp(p (tau_s - tau_y)/(s0 - tau_y)) - 1),
    tau(0) = tau_y (PTW 2003 eq. (5); p -> 0: theta (tau_s - tau)/(tau_s - tau_y)), integrated numerically."""
    law = get_law("ptw")
    worst = 0.0
    for rate, T in itertools.product([1e-3, 1e3, 1e7], [77.0, 298.0, 700.0]):
        tau_s, tau_y = ptw_stresses(values, rate, T, 1.0)
        if tau_s <= tau_y:                               # nothing to integrate (covered by the closed form)
            continue
        s0, p, theta = values["s0"], values["p"], values["theta"]

        def slope(psi, tau, tau_s=tau_s, tau_y=tau_y, s0=s0, p=p, theta=theta):
            if p == 0:
                return theta * (tau_s - tau) / (tau_s - tau_y)
            return theta * np.expm1(p * (tau_s - tau) / (s0 - tau_y)) / np.expm1(p * (tau_s - tau_y) / (s0 - tau_y))

        solution = solve_ivp(slope, (0.0, STRAINS[-1]), [tau_y], method="DOP853", t_eval=STRAINS, rtol=1e-13,
                             atol=1e-18)
        G_MPa = 1e3 * values["G0_GPa"] * (1 - values["alpha"] * T / values["T_melt_K"])
        worst = max(worst, relative_error(flow_stress_curve(law, values, STRAINS, rate, T, material=AL5083), 2 * G_MPa * solution.y[0]))
    assert worst <= 1e-9


def test_steinberg_guinan_modulus_and_melt_against_their_definitions():
    """G'_P = dG/dP and G'_T = dG/dT at (0, 300 K, eta = 1); d ln T_m / d ln eta = 2 (gamma(eta) - 1/3)
    with gamma(eta) = gamma0 - a (1 - 1/eta) (the Lindemann law SG integrate), by central differences."""
    for values in SG_SETS:
        params = code_parameters(get_law("sg"), values, material=AL5083)
        dP, dT = 1e-6, 1e-3                              # Mbar, K
        dG_dP = (steinberg_guinan_shear_modulus(params, dP, 300.0, 1.0)
                 - steinberg_guinan_shear_modulus(params, -dP, 300.0, 1.0)) / (2 * dP)
        dG_dT = (steinberg_guinan_shear_modulus(params, 0.0, 300.0 + dT, 1.0)
                 - steinberg_guinan_shear_modulus(params, 0.0, 300.0 - dT, 1.0)) / (2 * dT)
        assert dG_dP == pytest.approx(values["dGdP"], rel=1e-7)
        assert dG_dT / params.G0 == pytest.approx(values["dGdT_over_G0_per_K"], rel=1e-7)
        for eta in (0.95, 1.0, 1.1, 1.3):
            h = 1e-6
            slope = (math.log(steinberg_guinan_melt_temperature(params, eta * math.exp(h)))
                     - math.log(steinberg_guinan_melt_temperature(params, eta * math.exp(-h)))) / (2 * h)
            grueneisen = params.gamma0 - params.a * (1 - 1 / eta)
            assert slope == pytest.approx(2 * (grueneisen - 1 / 3), rel=1e-7)


@pytest.fixture(scope="module")
def impala_functions():
    """impala's physics functions; its import sets numpy's error state to 'raise' (restored here) and
    loads matplotlib, pandas and seaborn, which is why impala is not a dependency."""
    state = np.geterr()
    try:
        from impala.physics import physical_models_functions
    except ImportError:
        pytest.skip("impala-calib not installed: `pip install impala-calib` to compare PTW and SG with LANL's impala")
    finally:
        np.seterr(**state)
    return physical_models_functions


def _array(value, size):
    return np.full(size, float(value))


def test_ptw_against_impala(impala_functions):
    """Against impala's PTW_Yield_Stress with its Simple_Shear_Modulus (the same G law), at eta = 1
    (impala uses rho0 in xi_dot) and rates in 1/us (impala's convention with Mbar and g/cc). impala's
    N_A is 6.022e23: its molar mass is scaled so that N_A / M matches."""
    f = impala_functions
    law = get_law("ptw")
    worst = 0.0
    for values in PTW_SETS:
        for rate, T in itertools.product(RATES, TEMPERATURES):
            size = len(STRAINS)
            G = f.Simple_Shear_Modulus(_array(values["G0_GPa"] / 100, size), _array(values["alpha"], size),
                                       _array(T, size), _array(values["T_melt_K"], size))
            kw = {k: _array(values[k], size) for k in ("p", "kappa", "s0", "y0", "y1", "y2", "beta", "theta")}
            impala = f.PTW_Yield_Stress(**kw, sInf=_array(values["sinf"], size), yInf=_array(values["yinf"], size),
                                        lgamma=_array(math.log(values["gamma"]), size), edot=_array(rate * 1e-6, size),
                                        rho0=_array(values["rho0_g_per_cc"], size),
                                        matomic=_array(values["M_g_per_mol"] * 6.022e23 / Avogadro, size),
                                        shear=G, eps=STRAINS.copy(), T=_array(T, size),
                                        Tmelt=_array(values["T_melt_K"], size))
            worst = max(worst, relative_error(flow_stress_curve(law, values, STRAINS, rate, T, material=AL5083), impala * 1e5))
    assert worst <= 1e-10


def test_steinberg_guinan_against_impala(impala_functions):
    """Against impala's Stein_Flow_Stress with its Stein_Shear_Modulus (no pressure term: P = 0, eta = 1)."""
    f = impala_functions
    law = get_law("sg")
    worst = 0.0
    size = len(STRAINS)
    for values in SG_SETS:
        T_melt = values.get("T_m0_K", 1220.0)
        for T in TEMPERATURES:
            G = f.Stein_Shear_Modulus(_array(values["G0_GPa"], size), _array(-values["dGdT_over_G0_per_K"], size),
                                      _array(T, size), _array(T_melt, size))
            impala = f.Stein_Flow_Stress(_array(values["Y0_GPa"], size), _array(values["beta"], size),
                                         _array(values["n"], size), _array(values["Ymax_GPa"], size),
                                         _array(values["G0_GPa"], size), _array(values.get("eps_i", 0.0), size),
                                         G, STRAINS.copy(), _array(T, size), _array(T_melt, size))
            worst = max(worst, relative_error(flow_stress_curve(law, values, STRAINS, 1.0, T, material=AL5083), impala * 1e3))
    assert worst <= 1e-10


# ---------------------------------------------------------------------------------------------- 3b. solver floors
def _box_draws(name: str, count: int, rng, **ranges) -> list[tuple[dict, tuple]]:
    """(user values, code tuple) drawn uniformly from the law's prior box (config/models.yaml) and any
    further `ranges` (name=(low, high)), constraints met."""
    box, law, sets = load_boxes()[name], get_law(name), []
    while len(sets) < count:
        values = {k: rng.uniform(b.low, b.high) for k, b in box.items()}
        values.update({k: rng.uniform(low, high) for k, (low, high) in ranges.items()})
        try:
            sets.append((values, code_parameters(law, values, material=AL5083)))
        except InputError:
            continue
    return sets


def _random_state(rng) -> tuple[float, float, float, float, float]:
    """(eps_p, equivalent strain rate 1/us, T K, P Mbar, eta): rates from 0 to 1e9 /s (PTW's r far above 1,
    its overdriven branches), temperatures to the melt, compressions and tensions."""
    eps_p = 0.0 if rng.uniform() < 0.1 else 10 ** rng.uniform(-6, 0)
    rate = 0.0 if rng.uniform() < 0.1 else 10 ** rng.uniform(-6, 9) * PER_S_TO_PER_US
    return eps_p, rate, rng.uniform(1.0, 1000.0), rng.uniform(-0.01, 0.15), rng.uniform(0.85, 1.4)


NO_MEMORY = (0.0, 0.0, math.inf)         # a cell's floor slots before any evaluation (solver.initial_mesh)


@pytest.mark.parametrize("name", ["steinberg-guinan", "ptw", "zerilli-armstrong"])
def test_law_floor_lies_below_the_flow_stress(name):
    """The solver skips a law's flow stress while the elastic trial lies inside its floor
    (`law_flow_stress_floor`, from the cached `law_hardening`): exact only if the floor never exceeds
    the flow stress. Checked over 40 parameter sets drawn from the prior box and 400 random states each;
    and the flow stress with the cell's G (`law_flow_stress_at`) equals the law's own bit for bit."""
    law = get_law(name)
    rng = np.random.default_rng(20261128)
    hits = 0
    for _, code in _box_draws(name, 40, rng):
        for _ in range(400):
            eps_p, rate, T, P, eta = _random_state(rng)
            G = law_shear_modulus(code, 0.27, P, T, eta)
            if G <= 0.0:
                continue
            Y = law.flow_stress(code, eps_p, rate, T, P, eta)
            assert law_flow_stress_at(code, G, eps_p, rate, T, P, eta) == Y
            floor = law_flow_stress_floor(code, law_hardening(code, eps_p), G, T, eta, *NO_MEMORY)
            assert LAW_FLOOR_SLACK * floor <= Y, (code, eps_p, rate, T, P, eta, floor, Y)
            hits += floor > 0.5 * Y
    assert hits > 1000          # the floor is not vacuous: it reaches half the flow stress in many states


def test_steinberg_guinan_melt_bound_lies_below_the_melt_temperature():
    """G(P, T, eta) evaluates the melt law only where T reaches its cheap lower bound: exact only if the bound
    never exceeds T_melt(eta). 2000 sets (the box, gamma0 0.5-3, a 0-3, T_m0 500-2000 K) x 50 eta in
    0.5-2; and the bound is close near eta = 1, where the shots' cells are."""
    rng = np.random.default_rng(1)
    ranges = dict(gamma0=(0.5, 3.0), a=(0.0, 3.0), T_m0_K=(500.0, 2000.0))
    for values, code in _box_draws("steinberg-guinan", 2000, rng, **ranges):
        for eta in rng.uniform(0.5, 2.0, 50):
            assert steinberg_guinan_melt_temperature_below(code, eta) <= steinberg_guinan_melt_temperature(code, eta)
        ratio = steinberg_guinan_melt_temperature_below(code, 1.02) / steinberg_guinan_melt_temperature(code, 1.02)
        assert ratio > 0.99, values


# ---------------------------------------------------------------------------------------------- 4. declarations
UNIT_SUFFIX = {"MPa": "_MPa", "GPa": "_GPa", "K": "_K", "1/K": "_per_K", "1/s": "_per_s", "g/mol": "_g_per_mol",
               "g/cc": "_g_per_cc"}


def test_declarations_and_boxes_agree():
    boxes = load_boxes()
    assert set(boxes) == set(LAWS)
    for name, law in LAWS.items():
        assert len(set(law.names())) == len(law.params)
        assert [p.field for p in law.params] == list(law.code_type._fields)
        calibrated = [p.name for p in law.params if p.default is None and p.material is None]
        assert set(calibrated) <= set(boxes[name]), name          # every calibrated parameter has a box
        for param in law.params:                                  # names carry their unit
            assert param.unit == "-" or param.name.endswith(UNIT_SUFFIX[param.unit]), param.name


def test_nominal_values_give_a_positive_flow_stress():
    boxes = load_boxes()
    for name in ("johnson-cook", "steinberg-guinan"):
        values = {k: b.nominal for k, b in boxes[name].items()}
        stress = flow_stress_curve(get_law(name), values, STRAINS, 1e5, 310.0, 2.0, 1.02, material=AL5083)
        assert np.all(np.isfinite(stress)) and np.all(stress > 0) and np.all(np.diff(stress) >= 0)


def test_unit_conversions():
    jc = code_parameters(get_law("jc"), dict(A_MPa=270, B_MPa=470, C=0.01, n=0.6, m=1.2), material=AL5083)
    assert jc.A == pytest.approx(0.0027) and jc.rate_ref == pytest.approx(1e-6)
    sg = code_parameters(get_law("sg"), SG_SETS[0], material=AL5083)
    assert sg.G0 == pytest.approx(0.276) and sg.Y0 == pytest.approx(0.0029)


# ---------------------------------------------------------------------------------------------- CLI
JC_ARGS = ["--param", "A_MPa=270", "--param", "B_MPa=470", "--param", "C=0.0105", "--param", "n=0.6",
           "--param", "m=1.2"]
AL5083_ARGS = ["--material", "al5083"]      # T_ref_K, T_melt_K and the reference rate of Johnson-Cook


def test_cli_prints_a_table(capsys):
    assert main(["flow-stress", "--model", "jc", *JC_ARGS, *AL5083_ARGS, "--strain-rate", "1e5", "--temperature",
                 "310"]) == 0
    rows = [line.split() for line in capsys.readouterr().out.splitlines() if not line.startswith(("#", " plastic"))]
    rows = [r for r in rows if r and r[0] != "plastic_strain"]
    strains = np.array([float(r[0]) for r in rows])
    stress = np.array([float(r[1]) for r in rows])
    assert strains[0] == 0.0 and strains[-1] == pytest.approx(0.2) and len(rows) == 11
    want = jc_closed(JC_SETS[0], strains, 1e5, 310.0)
    assert np.allclose(stress, want, rtol=1e-5)


@pytest.mark.parametrize("argv, message", [
    (["--model", "voce", "--strain-rate", "1", "--temperature", "300"], "unknown strength model 'voce'"),
    (["--model", "jc", *JC_ARGS, "--param", "D=1", "--strain-rate", "1", "--temperature", "300"],
     "unknown parameter D"),
    (["--model", "jc", "--param", "A_MPa=270", "--strain-rate", "1", "--temperature", "300"],
     "missing parameter B_MPa, C, n, m"),
    (["--model", "jc", *JC_ARGS[:-2], "--param", "m=abc", "--strain-rate", "1", "--temperature", "300"],
     "'abc' is not a number"),
    (["--model", "za", "--param", "C0_MPa=-50", "--param", "C2_MPa=100", "--param", "C3_per_K=0.001",
      "--param", "C4_per_K=0.0001", "--strain-rate", "1", "--temperature", "300"], "flow stress -50.0 MPa"),
    (["--model", "ptw", *[f"--param={k}={v}" for k, v in (PTW_SETS[0] | {"y0": 0.01}).items()],
      "--strain-rate", "1", "--temperature", "300"], "violate y0 < s0"),
    (["--model", "jc", *JC_ARGS, "--strain-rate", "nan", "--temperature", "300"], "--strain-rate: nan"),
])
def test_cli_errors_are_one_line(capsys, argv, message):
    assert main(["flow-stress", *argv]) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1 and "Traceback" not in err


@pytest.mark.parametrize("temperature, molten", [(310.0, False), (893.0, True), (3000.0, True)])
def test_cli_says_when_the_state_is_molten(capsys, temperature, molten):
    """Johnson-Cook's flow stress is zero at and above T_melt_K (Al-5083's 893 K): the table says why."""
    assert main(["flow-stress", "--model", "jc", *JC_ARGS, *AL5083_ARGS, "--strain-rate", "1e5", "--temperature",
                 str(temperature), "--points", "3"]) == 0
    out = capsys.readouterr().out
    note = f"# molten: T {temperature:g} K is at or above the law's melting temperature 893 K"
    assert (note in out) == molten
    stress = [float(line.split()[1]) for line in out.splitlines()[-3:]]
    assert (max(stress) == 0.0) == molten
