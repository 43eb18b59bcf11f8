"""Johnson-Cook (1983) as a strength-law kernel: a thin wrapper over today's `hydro.strength` functions.

    Y = (A + B eps_p^n) (1 + C ln(epsdot / epsdot_0)) (1 - T*^m),   T* = (T - T_ref) / (T_melt - T_ref)

with the project's conventions (docs/hydro.md, `hydro/strength.py`): the rate ratio floored at 1,
n = 0 meaning eps_p^0 = 1, no softening at T* <= 0 and none left at T* >= 1: the product of `hardening`,
`rate_factor` and `thermal_factor` (`hydro.strength`) in that order (tests/test_strength_laws.py).

The solver's floor (`shockcal.hydro.plastic_return.plastic_return`): the cell caches A + B eps_p^n in `hard`
(`johnson_cook_hardening`) and remembers, at its last full evaluation that found it elastic, the thermal
factor 1 - T*^m at that temperature (`flow_floor`), a lower bound of it FLOOR_MARGIN_K hotter
(`floor_hotter`, `thermal_factor_below`: no extra pow) and the temperature (`floor_T`). The floor is `hard`
times the remembered factor that holds at the cell's temperature: a lower bound of the flow stress at any
rate (the thermal factor falls with T, `hard` holds the current plastic strain, the rate factor is >= 1), so
an elastic cell costs no pow and no log.

The consistent return (`johnson_cook_plastic_increment`) has a closed form up to one scalar equation: with
the rate-free flow stress Y0 = (A + B eps_p^n)(1 - T*^m), the increment d = d_ref e^x at the reference rate's
increment d_ref = dt epsdot_0 solves

    3/2 |s_trial| - 3 G d_ref e^x = Y0 (1 + C x),   x = ln(d / d_ref) > 0,

the form whose root is a Lambert W; solved by Halley's steps in x from an upper bound of the root (each
term of the left side alone), the increment read from the last step's exponential (e^step to second order).
"""

from __future__ import annotations

import math
from typing import NamedTuple

from numba import njit

from shockcal.hydro.series import EXP_STEP_MAX, NO_SERIES, exp_small, power_growth
from shockcal.hydro.strength import hardening, rate_factor, thermal_factor, thermal_factor_below

FLOOR_MARGIN_K = 1.0       # a cell's hotter floor holds up to this much above the temperature it was set at
FLOOR_SLACK = 1.0 - 1e-12  # keeps the remembered thermal factor below the exact one through rounding
STEP_STOP = 1e-6           # a Halley step in x = ln(d / d_ref) this small leaves an error about 1e-18 (cubic)
NEWTON_MAX_STEPS = 60
RATE_FREE = 0.0           # the plastic strain rate (1/us) of the rate-free yield surface
# Without a rate term (C = 0) the return is the rate-free radial return, whose switching between
# yield and no yield carries a last-bit change of the flow stress into the trace (1e-6 m/s where a
# rate-dependent run moves 1e-11 m/s): there the series are not used, and such runs keep the radial return's
# arithmetic bit for bit (tests/test_hydro.py's C = 0 traces stored before the rate term moved into the return).


class JohnsonCook(NamedTuple):
    """Johnson-Cook parameters in code units."""

    A: float               # Mbar
    B: float               # Mbar
    C: float               # -
    n: float               # -
    m: float               # -
    T_ref: float           # K
    T_melt: float          # K
    rate_ref: float        # 1/us


@njit(cache=True, error_model="numpy")
def johnson_cook_flow_stress(law, eps_p, strain_rate, T, P, eta):
    """Flow stress (Mbar) at equivalent plastic strain `eps_p`, equivalent strain rate `strain_rate`
    (1/us), temperature `T` (K); pressure `P` (Mbar) and density ratio `eta` are not used."""
    return (hardening(law.A, law.B, law.n, eps_p) * rate_factor(law.C, strain_rate, law.rate_ref)
            * thermal_factor(law.m, _homologous(law, T)))


@njit(cache=True, error_model="numpy")
def johnson_cook_flow_stress_from_hardening(law, hard, strain_rate, T):
    """The flow stress (Mbar) from the cell's cached hardening `hard` (A + B eps_p^n, Mbar), the equivalent strain
    rate (1/us) and T (K): `johnson_cook_flow_stress` bit for bit (the same product in the same order), without
    recomputing eps_p^n."""
    return hard * rate_factor(law.C, strain_rate, law.rate_ref) * thermal_factor(law.m, _homologous(law, T))


@njit(cache=True, error_model="numpy")
def _homologous(law, T):
    """T* = (T - T_ref) / (T_melt - T_ref), in the hydrocode's order of operations."""
    return (T - law.T_ref) * (1.0 / (law.T_melt - law.T_ref))


@njit(cache=True, error_model="numpy")
def johnson_cook_hardening(law, eps_p):
    """A + B eps_p^n (Mbar), the hardening the solver caches per cell."""
    return hardening(law.A, law.B, law.n, eps_p)


@njit(cache=True, error_model="numpy")
def johnson_cook_flow_stress_floor(law, hard, G, T, eta, flow_floor, floor_hotter, floor_T):
    """A lower bound (Mbar) of the flow stress at any rate: `hard` (A + B eps_p^n, Mbar) times the thermal
    factor the cell remembered at floor_T (K) while T (K) is no hotter, the one FLOOR_MARGIN_K hotter up to
    that, else -1 (none). G and eta are not used."""
    if T <= floor_T:
        return hard * flow_floor
    if T <= floor_T + FLOOR_MARGIN_K:
        return hard * floor_hotter
    return -1.0


@njit(cache=True, error_model="numpy")
def johnson_cook_remember_floor(law, G, eps_p, T, eta, flow_floor, floor_hotter, floor_T):
    """The cell's remembered thermal factors after a full evaluation found it elastic at T (K): 1 - T*^m
    and its lower bound FLOOR_MARGIN_K hotter, each just below by FLOOR_SLACK, and T."""
    homologous = _homologous(law, T)
    thermal = thermal_factor(law.m, homologous)
    margin = FLOOR_MARGIN_K * (1.0 / (law.T_melt - law.T_ref))
    return (FLOOR_SLACK * thermal, FLOOR_SLACK * thermal_factor_below(law.m, homologous, thermal, margin), T)


@njit(cache=True, error_model="numpy")
def johnson_cook_rate_free_flow_stress(law, hard, T, power_T, power):
    """The flow stress (Mbar) at zero plastic rate, `johnson_cook_flow_stress_from_hardening` at rate 0, from the
    cell's cached hardening `hard` (Mbar) at T (K), with T*^m from the cell's remembered `power` = T*^m at
    `power_T` (K) by the binomial series (`series.power_growth`) where it holds, else by the pow: (Y0, T, the
    new T*^m); at T* outside (0, 1) or m = 0 the thermal factor's own conventions, the memory unchanged; without a
    rate term (C <= 0) the pow always (the note at RATE_FREE)."""
    homologous = _homologous(law, T)
    if homologous <= 0.0 or homologous >= 1.0 or law.m == 0.0 or law.C <= 0.0:
        return hard * rate_factor(law.C, RATE_FREE, law.rate_ref) * thermal_factor(law.m, homologous), power_T, power
    growth = power_growth((T - power_T) / (power_T - law.T_ref), law.m) if power > 0.0 else NO_SERIES
    power = homologous**law.m if growth == NO_SERIES else power + power * growth
    return hard * (1.0 - power), T, power


@njit(cache=True, error_model="numpy")
def johnson_cook_hardening_after(law, hard, eps_p, d_eps):
    """A + B (eps_p + d_eps)^n (Mbar) from the cell's hard = A + B eps_p^n: hard + (hard - A) ((1 + d_eps /
    eps_p)^n - 1) by the binomial series (`series.power_growth`) where it holds, else `johnson_cook_hardening`
    (always without a rate term, C <= 0: the note at RATE_FREE)."""
    growth = power_growth(d_eps / eps_p, law.n) if eps_p > 0.0 and law.C > 0.0 else NO_SERIES
    if growth == NO_SERIES:
        return johnson_cook_hardening(law, eps_p + d_eps)
    return hard + (hard - law.A) * growth


@njit(cache=True, error_model="numpy")
def johnson_cook_plastic_increment(law, equivalent, rate_free, G, dt, hard, eps_p, T, P, eta):
    """The consistent return's plastic strain increment d and the flow stress Y (Mbar) at the step's plastic
    rate d / dt (module docstring), for a trial von Mises stress `equivalent` (Mbar) above the rate-free flow
    stress `rate_free` (Mbar), shear modulus G (Mbar) and time step dt (us); the cell's state (hard, eps_p,
    T, P, eta) is in `rate_free` already. Below the reference rate (or with C <= 0) the rate-free radial
    return: d = (equivalent - rate_free) / (3 G), Y = rate_free. Solved from the upper bound
    (`johnson_cook_plastic_increment_warm` without a warm start)."""
    d, Y, _, _ = johnson_cook_plastic_increment_warm(law, equivalent, rate_free, G, dt, hard, eps_p, T, P, eta,
                                                     0.0, 0.0)
    return d, Y


@njit(cache=True, error_model="numpy")
def johnson_cook_plastic_increment_warm(law, equivalent, rate_free, G, dt, hard, eps_p, T, P, eta, x_warm,
                                        rate_warm):
    """`johnson_cook_plastic_increment`'s (d, Y) and the cell's new warm start (x, d / dt): the Halley steps
    start at the cell's last plastic step, x_warm = ln(rate_warm / epsdot_0) and its plastic rate rate_warm
    (1/us), without a log or an exp, where the Newton step from there is at most EXP_STEP_MAX (the residual is
    concave with its curvature below its slope, so the root is about that close and each later step takes
    e^step's series, `series.exp_small`); else (rate_warm = 0: none) from the upper bound. Below the
    reference rate (or C <= 0) the radial return, the warm start kept."""
    overstress = equivalent - rate_free
    d_free, d_ref = overstress / (3.0 * G), dt * law.rate_ref
    slope_x = rate_free * law.C                     # dY/dx
    if d_free <= d_ref or slope_x <= 0.0:
        return d_free, rate_free, x_warm, rate_warm
    elastic_ref = 3.0 * G * d_ref                   # the stress 3 G d_ref e^x at x = 0
    x, elastic = x_warm, 3.0 * G * dt * rate_warm   # 3 G d_ref e^x_warm
    if not (rate_warm > 0.0 and abs(overstress - elastic - slope_x * x) <= EXP_STEP_MAX * (elastic + slope_x)):
        x = min(overstress / slope_x, math.log(overstress / elastic_ref))   # each term alone: above the root
        elastic = elastic_ref * math.exp(x)
    for _ in range(NEWTON_MAX_STEPS):
        residual, slope = overstress - elastic - slope_x * x, elastic + slope_x     # r and -dr/dx
        step = 2.0 * residual * slope / (2.0 * slope * slope + residual * elastic)   # Halley's step
        x += step
        if abs(step) <= STEP_STOP:
            break
        elastic = elastic * exp_small(step) if abs(step) <= EXP_STEP_MAX else elastic_ref * math.exp(x)
    d = elastic / (3.0 * G) * (1.0 + step * (1.0 + 0.5 * step))
    return d, rate_free * (1.0 + law.C * x), x, d / dt
