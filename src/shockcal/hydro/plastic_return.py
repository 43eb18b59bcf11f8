"""A cell's return onto its strength law after the elastic trial (numba kernels on scalars, code units).

One return serves every law of the registry (`shockcal.hydro.laws`). A trial inside the rate-free yield
surface (the flow stress at the cell's plastic strain and zero plastic rate, where every law's rate term is
at its floor) is elastic; outside it the cell returns onto the flow stress at the plastic strain rate of
the step being solved (`shockcal.hydro.consistent_return`), which for a rate-free law (Steinberg-Guinan) is
the radial return. The rate-free flow stress is evaluated only when the trial leaves the law's floor
(`law_flow_stress_floor`, a lower bound of it at any rate: Johnson-Cook's A + B eps_p^n times the thermal
factor it remembered, Steinberg-Guinan's exact flow stress, PTW's quasi-static one, Zerilli-Armstrong's C0),
read from the hardening the cell caches in `hard` and the floor it remembers in the cell's three floor slots.
The skip is exact: a skipped cell is one the full evaluation would have left elastic. `plastic_return`,
`cell_shear_modulus` and `initial_hardening` are compiled per law tuple type (`laws.kernels`) and inlined
into the solver's `update_cells`.
"""

from __future__ import annotations

import math

from numba import njit

from shockcal.hydro.consistent_return import law_plastic_increment_warm
from shockcal.hydro.laws.kernels import (
    law_flow_stress_floor,
    law_hardening,
    law_hardening_after,
    law_rate_free_flow_stress,
    law_remember_floor,
    law_shear_modulus,
)

LAW_FLOOR_SLACK = 1.0 - 1e-9  # keeps a law's floor below its flow stress, computed along another path
NO_MEMORY = (0.0, 0.0, 0.0, 0.0)  # a fresh cell's (power_T, power, x_warm, rate_warm): nothing to reuse yet


@njit(cache=True, error_model="numpy", inline="always")
def plastic_return(s_trial, T_cell, dt, P, eta, G, eps_p, hard, flow_floor, floor_hotter, floor_T, strength, material,
                   memory):
    """A cell's return after its elastic trial deviator s_trial (Mbar) over a step dt (us), on scalars: (s,
    d eps_p, and the cell's new eps_p, hard, flow_floor, floor_hotter, floor_T, memory). Elastic while the trial
    lies inside the law's floor (from the cell's cached hardening `hard`, its remembered floor in the flow_floor,
    floor_hotter and floor_T slots, and G) or inside the rate-free flow stress at the cell's plastic strain,
    temperature (K), pressure (Mbar), density ratio and shear modulus G (Mbar); else the consistent return
    onto the flow stress at the step's plastic rate. `hard` follows the plastic strain (`law_hardening_after`); an
    elastic full evaluation sets the remembered floor (`law_remember_floor`). `memory` = (power_T, power,
    x_warm, rate_warm) is what a cell that stays plastic reuses (`state.Cells`; NO_MEMORY: none yet): the law's thermal power at a
    temperature (`law_rate_free_flow_stress`) and the warm start of its solve (`law_plastic_increment_warm`). A
    cell with G = 0 (molten) carries no deviator and gains no plastic strain. `material` is not used (the law's
    tuple holds its material constants). Scalars in and out: inlined code that indexes the cell arrays cost the
    104S run 23% more CPU (reference counts per cell)."""
    if G <= 0.0:
        return 0.0, 0.0, eps_p, hard, flow_floor, floor_hotter, floor_T, memory
    law, equivalent = strength.law, 1.5 * abs(s_trial)
    if equivalent <= LAW_FLOOR_SLACK * law_flow_stress_floor(law, hard, G, T_cell, eta, flow_floor, floor_hotter,
                                                              floor_T):
        return s_trial, 0.0, eps_p, hard, flow_floor, floor_hotter, floor_T, memory
    power_T, power, x_warm, rate_warm = memory
    rate_free, power_T, power = law_rate_free_flow_stress(law, hard, G, eps_p, T_cell, P, eta, power_T, power)
    if equivalent <= rate_free:
        flow_floor, floor_hotter, floor_T = law_remember_floor(law, G, eps_p, T_cell, eta, flow_floor, floor_hotter,
                                                               floor_T)
        return s_trial, 0.0, eps_p, hard, flow_floor, floor_hotter, floor_T, (power_T, power, x_warm, rate_warm)
    d_eps, flow, x_warm, rate_warm = law_plastic_increment_warm(law, equivalent, rate_free, G, dt, hard, eps_p, T_cell,
                                                                P, eta, x_warm, rate_warm)
    hard = law_hardening_after(law, hard, eps_p, d_eps)
    return (math.copysign(flow / 1.5, s_trial), d_eps, eps_p + d_eps, hard, flow_floor, floor_hotter, floor_T,
            (power_T, power, x_warm, rate_warm))


@njit(cache=True, error_model="numpy", inline="always")
def cell_shear_modulus(strength, P, T, eta):
    """The shear modulus (Mbar) of a cell at pressure P (Mbar), temperature T (K) and density ratio eta:
    the run's constant G, or the law's G(P, T, eta) for laws that have one (Steinberg-Guinan, PTW)."""
    return law_shear_modulus(strength.law, strength.G, P, T, eta)


@njit(cache=True, error_model="numpy")
def initial_hardening(strength):
    """The cells' initial `hard`: the law's hardening at eps_p = 0 (Mbar)."""
    return law_hardening(strength.law, 0.0)
