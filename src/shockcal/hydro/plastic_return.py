"""A cell's return onto its strength law after the elastic trial (numba kernels on scalars, code units).

Johnson-Cook (`Strength`) is evaluated only when the trial leaves the cell's flow-stress floor (`floor_at`,
`new_floors`, `inside_floor`): a lower bound of (A + B eps_p^n)(1 - T*^m), valid while the cell is no hotter
than when the floor was set (`FLOOR_MARGIN_K` more for the hotter floor), so an elastic cell costs no pow or
log. Any other law (`LawStrength`) is evaluated only when the trial leaves the law's floor
(`law_flow_stress_floor`: Steinberg-Guinan's exact flow stress, PTW's quasi-static one or the one it
remembered at its last elastic evaluation, Zerilli-Armstrong's C0), read from the hardening the cell caches
in `hard` and the floor it remembers in the Johnson-Cook floor slots. Both skips are exact: a skipped
cell is one the full evaluation would have left elastic. `plastic_return`, `cell_shear_modulus` and
`initial_hardening` pick their branch when numba compiles, by the type of the strength tuple, and are inlined
into the solver's `update_cells`.
"""

from __future__ import annotations

from numba import njit
from numba.extending import overload

from shockcal.hydro.laws.kernels import (
    law_flow_stress_at,
    law_flow_stress_floor,
    law_hardening,
    law_remember_floor,
    law_shear_modulus,
)
from shockcal.hydro.state import Strength
from shockcal.hydro.strength import (
    equivalent_strain_rate,
    flow_stress,
    hardening,
    radial_return,
    rate_factor,
    thermal_factor,
    thermal_factor_below,
)

FLOOR_MARGIN_K = 1.0       # a cell's flow-stress floor holds up to this much above the temperature it was set at
FLOOR_SLACK = 1.0 - 1e-12  # keeps the floor below the flow stress through rounding (products in another order)
LAW_FLOOR_SLACK = 1.0 - 1e-9  # the same for a law's floor, computed along another path than its flow stress


@njit(cache=True, error_model="numpy")
def homologous_temperature(T, material):
    """T* = (T - T_ref) / (T_melt - T_ref)."""
    return (T - material.T_ref) * (1.0 / (material.T_melt - material.T_ref))


@njit(cache=True, error_model="numpy")
def johnson_cook_return(s_trial, T_cell, strain_rate, hard, strength, material):
    """(s, d eps_p, thermal factor, a lower bound of it FLOOR_MARGIN_K hotter): the trial deviator
    returned onto the Johnson-Cook yield surface at the cell's temperature (K) and current strain
    rate (1/us) if outside it, and the thermal factors of the cell's floors."""
    homologous = homologous_temperature(T_cell, material)
    thermal = thermal_factor(strength.m, homologous)
    s_new, d_eps = radial_return(s_trial, flow_stress(hard, thermal, strength.C, strain_rate, strength.rate_ref),
                                 strength.G)
    margin = FLOOR_MARGIN_K * (1.0 / (material.T_melt - material.T_ref))
    return s_new, d_eps, thermal, thermal_factor_below(strength.m, homologous, thermal, margin)


@njit(cache=True, error_model="numpy")
def floor_at(T_cell, flow_floor, floor_hotter, floor_T):
    """A cell's flow-stress floor (Mbar) at temperature T_cell (K), from its cached floors: the one set at
    floor_T (K) while the cell is no hotter, the hotter one up to FLOOR_MARGIN_K above it, else -1 (none)."""
    if T_cell <= floor_T:
        return flow_floor
    if T_cell <= floor_T + FLOOR_MARGIN_K:
        return floor_hotter
    return -1.0


@njit(cache=True, error_model="numpy")
def new_floors(hard, thermal, thermal_hotter):
    """(flow_floor, floor_hotter) after a full evaluation of the flow stress: A + B eps_p^n (Mbar) times
    the thermal factor at the cell's temperature and its bound FLOOR_MARGIN_K hotter, each just below by
    FLOOR_SLACK."""
    return FLOOR_SLACK * hard * thermal, FLOOR_SLACK * hard * thermal_hotter


@njit(cache=True, error_model="numpy")
def inside_floor(equivalent_stress, flow_floor, strain_rate, strength):
    """Whether a trial von Mises stress is provably elastic: inside the rate-free floor, or (one log)
    inside the floor times the Johnson-Cook rate factor. A negative floor means none holds."""
    if equivalent_stress <= flow_floor:
        return True
    if flow_floor <= 0.0 or strength.C == 0.0:     # no floor, or no rate term to raise it
        return False
    return equivalent_stress <= flow_floor * rate_factor(strength.C, equivalent_strain_rate(strain_rate),
                                                         strength.rate_ref)


def johnson_cook_floored_return(s_trial, T_cell, strain_rate, P, eta, G, eps_p, hard, flow_floor, floor_hotter,
                                floor_T, strength, material):
    """Johnson-Cook (`Strength`): elastic without evaluating the flow stress while the trial lies inside
    the cell's floor, else the return at the cell's temperature (K) and current strain rate (1/us), with
    the cell's new plastic strain, hardening and floors."""
    floor = floor_at(T_cell, flow_floor, floor_hotter, floor_T)
    if inside_floor(1.5 * abs(s_trial), floor, strain_rate, strength):
        return s_trial, 0.0, eps_p, hard, flow_floor, floor_hotter, floor_T
    s_new, d_eps, thermal, thermal_hotter = johnson_cook_return(s_trial, T_cell, strain_rate, hard, strength, material)
    if d_eps > 0.0:
        eps_p += d_eps
        hard = hardening(strength.A, strength.B, strength.n, eps_p)
    flow_floor, floor_hotter = new_floors(hard, thermal, thermal_hotter)
    return s_new, d_eps, eps_p, hard, flow_floor, floor_hotter, T_cell


def law_return(s_trial, T_cell, strain_rate, P, eta, G, eps_p, hard, flow_floor, floor_hotter, floor_T, strength,
               material):
    """Any law (`LawStrength`): elastic while the trial lies inside the law's floor (from the cell's cached
    hardening `hard`, its remembered floor in the flow_floor, floor_hotter and floor_T slots, and G), else
    the trial returned onto the law's flow stress at the cell's plastic strain, equivalent strain rate
    (1/us), temperature (K), pressure (Mbar) and density ratio, with the cell's shear modulus G (Mbar).
    `hard` follows the plastic strain (`law_hardening`); an elastic full evaluation sets the remembered
    floor (`law_remember_floor`). A cell with G = 0 (molten) carries no deviator and gains no plastic strain."""
    if G <= 0.0:
        return 0.0, 0.0, eps_p, hard, flow_floor, floor_hotter, floor_T
    law, rate = strength.law, equivalent_strain_rate(strain_rate)
    floor = law_flow_stress_floor(law, hard, G, rate, T_cell, eta, flow_floor, floor_hotter, floor_T)
    if 1.5 * abs(s_trial) <= LAW_FLOOR_SLACK * floor:
        return s_trial, 0.0, eps_p, hard, flow_floor, floor_hotter, floor_T
    s_new, d_eps = radial_return(s_trial, law_flow_stress_at(law, G, eps_p, rate, T_cell, P, eta), G)
    if d_eps > 0.0:
        eps_p += d_eps
        hard = law_hardening(law, eps_p)
    else:
        flow_floor, floor_hotter, floor_T = law_remember_floor(law, G, eps_p, rate, T_cell, eta, flow_floor,
                                                               floor_hotter, floor_T)
    return s_new, d_eps, eps_p, hard, flow_floor, floor_hotter, floor_T


def plastic_return(s_trial, T_cell, strain_rate, P, eta, G, eps_p, hard, flow_floor, floor_hotter, floor_T, strength,
                   material):
    """A cell's return after its elastic trial deviator s_trial (Mbar), on scalars: (s, d eps_p, and the
    cell's new eps_p, hard, flow_floor, floor_hotter, floor_T). `johnson_cook_floored_return` for
    `Strength`, `law_return` for `LawStrength`, chosen when numba compiles by the type of `strength`
    and inlined. Scalars in and out: inlined code that indexes the cell arrays cost the 104S run 23%
    more CPU (reference counts per cell)."""


def cell_shear_modulus(strength, P, T, eta):
    """The shear modulus (Mbar) of a cell at pressure P (Mbar), temperature T (K) and density ratio eta:
    the run's constant G, or the law's G(P, T, eta) for laws that have one (Steinberg-Guinan, PTW)."""


def initial_hardening(strength):
    """The cells' initial `hard`: Johnson-Cook's A + B 0^n (Mbar), or the law's hardening at eps_p = 0."""


def _is_johnson_cook(strength):
    return getattr(strength, "instance_class", None) is Strength


@overload(plastic_return, inline="always")
def _plastic_return(s_trial, T_cell, strain_rate, P, eta, G, eps_p, hard, flow_floor, floor_hotter, floor_T, strength,
                    material):
    return johnson_cook_floored_return if _is_johnson_cook(strength) else law_return


@overload(cell_shear_modulus, inline="always")
def _cell_shear_modulus(strength, P, T, eta):
    if _is_johnson_cook(strength):
        return lambda strength, P, T, eta: strength.G
    return lambda strength, P, T, eta: law_shear_modulus(strength.law, strength.G, P, T, eta)


@overload(initial_hardening, inline="always")
def _initial_hardening(strength):
    if _is_johnson_cook(strength):
        return lambda strength: hardening(strength.A, strength.B, strength.n, 0.0)
    return lambda strength: law_hardening(strength.law, 0.0)
