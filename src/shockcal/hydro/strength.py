"""Johnson-Cook's factors in uniaxial strain (SPEC section 2).

    Y = (A + B eps_p^n) (1 + C ln(epsdot_p / epsdot_0)) (1 - T*^m),  T* = (T - T_ref)/(T_melt - T_ref)

Conventions (also in docs/hydro.md):
- epsdot_p is the equivalent plastic strain rate of the step being solved, d eps_p / dt, as the paper
  writes it: the return solves for the plastic strain increment with the flow stress at that rate
  (`shockcal.hydro.consistent_return`, backward Euler, as production codes do). Evaluated instead on
  the step's total strain rate, explicitly beside the return (the convention before 2026-11-29, FLAG's),
  the rate term acted as a stiff viscosity whose explicit stability limit lies far below the CFL step:
  it rang at the rounding level and moved with the time step (docs/journal/hydro.md);
- the rate ratio is floored at 1: ln(max(epsdot / epsdot_0, 1)), so the rate term never softens;
- n = 0 means eps_p^0 = 1 (Y = A + B), including at eps_p = 0;
- T* <= 0 gives no thermal softening; T* >= 1 gives Y = 0 (melt);
- m -> 0: T*^m -> 1 for any T* > 0, so the material loses its strength as soon as it heats at all;
  m = 0 exactly is treated as that limit (Y = 0 for T* > 0, full strength at T* <= 0); no NaN.

In uniaxial strain the deviator is diag(s, -s/2, -s/2) with s = s_xx; von Mises equivalent stress
is 3|s|/2, and a return from the trial s onto a flow stress Y gains (3|s|/2 - Y)/(3G) of plastic strain.
"""

import math

from numba import njit

BOUND_ROUNDING = 1e-12     # absolute allowance for rounding in thermal_factor_below


@njit(cache=True, error_model="numpy")
def hardening(A, B, n, eps_p):
    """A + B eps_p^n (Mbar), with eps_p^0 = 1."""
    if n == 0.0:
        return A + B
    if eps_p <= 0.0:
        return A
    return A + B * eps_p**n


@njit(cache=True, error_model="numpy")
def rate_factor(C, strain_rate, strain_rate_ref):
    """1 + C ln(max(rate/rate_ref, 1))."""
    ratio = strain_rate / strain_rate_ref
    return 1.0 + C * math.log(ratio) if ratio > 1.0 else 1.0


@njit(cache=True, error_model="numpy")
def thermal_factor(m, homologous_T):
    """1 - T*^m with the conventions above."""
    if homologous_T <= 0.0:
        return 1.0
    if homologous_T >= 1.0 or m == 0.0:
        return 0.0
    return 1.0 - homologous_T**m


@njit(cache=True, error_model="numpy")
def thermal_factor_below(m, homologous_T, thermal, d_homologous_T):
    """A lower bound of thermal_factor(m, T* + dT*) from thermal = thermal_factor(m, T*), without a
    pow: with p = T*^m = 1 - thermal and x = dT*/T*, (1 + x)^m <= 1 + m x for m <= 1 (Bernoulli)
    and <= exp(m x) <= 1 / (1 - m x) for m x < 1; 0 (no bound) otherwise or at T* <= 0. The bound
    is lowered by BOUND_ROUNDING, far above the rounding of factors <= 1 (about 1e-15)."""
    if homologous_T <= 0.0:
        return 0.0
    x = d_homologous_T / homologous_T
    if m <= 1.0:
        growth = 1.0 + m * x
    elif m * x < 1.0:
        growth = 1.0 / (1.0 - m * x)
    else:
        return 0.0
    return max(1.0 - (1.0 - thermal) * growth - BOUND_ROUNDING, 0.0)
