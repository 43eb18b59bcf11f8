"""Johnson-Cook flow stress and von Mises radial return in uniaxial strain (SPEC section 2).

    Y = (A + B eps_p^n) (1 + C ln(epsdot / epsdot_0)) (1 - T*^m),  T* = (T - T_ref)/(T_melt - T_ref)

Conventions (also in docs/hydro.md):
- epsdot is the current step's total equivalent strain rate, (2/3)|d eps_xx/dt| in uniaxial strain
  (the usual explicit-code convention, and the one that reproduces FLAG's features). The paper writes
  the plastic rate; taken from the previous step (an explicit lag) it makes the rate term vanish
  wherever the stress relaxes slowly: a numerical artefact, not physics. The plastic rate is kept
  as a diagnostic only;
- the rate ratio is floored at 1: ln(max(epsdot / epsdot_0, 1)), so the rate term never softens;
- n = 0 means eps_p^0 = 1 (Y = A + B), including at eps_p = 0;
- T* <= 0 gives no thermal softening; T* >= 1 gives Y = 0 (melt);
- m -> 0: T*^m -> 1 for any T* > 0, so the material loses its strength as soon as it heats at all;
  m = 0 exactly is treated as that limit (Y = 0 for T* > 0, full strength at T* <= 0); no NaN.

In uniaxial strain the deviator is diag(s, -s/2, -s/2) with s = s_xx; von Mises equivalent stress
is 3|s|/2, and the increment of equivalent plastic strain of a radial return is (3|s|/2 - Y)/(3G).
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
def equivalent_strain_rate(strain_rate_xx):
    """Von Mises equivalent of a uniaxial-strain rate: (2/3)|d eps_xx/dt| (same unit as the input)."""
    return (2.0 / 3.0) * abs(strain_rate_xx)


@njit(cache=True, error_model="numpy")
def flow_stress(hardening_stress, thermal, C, strain_rate_xx, strain_rate_ref):
    """Johnson-Cook flow stress (Mbar) from A + B eps_p^n, 1 - T*^m and the current total strain rate."""
    return hardening_stress * rate_factor(C, equivalent_strain_rate(strain_rate_xx), strain_rate_ref) * thermal


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


@njit(cache=True, error_model="numpy")
def radial_return(s_trial, flow_stress, G):
    """Return (s, d eps_p): the trial deviator scaled back onto the yield surface if outside it."""
    equivalent = 1.5 * abs(s_trial)
    if equivalent <= flow_stress:
        return s_trial, 0.0
    s = math.copysign(flow_stress / 1.5, s_trial)
    return s, (equivalent - flow_stress) / (3.0 * G)
