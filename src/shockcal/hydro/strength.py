"""Johnson-Cook flow stress and von Mises radial return in uniaxial strain (SPEC section 2).

    Y = (A + B eps_p^n) (1 + C ln(epsdot_p / epsdot_0)) (1 - T*^m),  T* = (T - T_ref)/(T_melt - T_ref)

Conventions (also in docs/hydro.md):
- the rate ratio is floored at 1: ln(max(epsdot_p / epsdot_0, 1)), so the rate term never softens;
- the plastic strain rate is the previous step's (explicit lag), as in most explicit hydrocodes;
- n = 0 means eps_p^0 = 1 (Y = A + B), including at eps_p = 0;
- T* <= 0 gives no thermal softening; T* >= 1 gives Y = 0 (melt);
- m -> 0: T*^m -> 1 for any T* > 0, so the material loses its strength as soon as it heats at all;
  m = 0 exactly is treated as that limit (Y = 0 for T* > 0, full strength at T* <= 0); no NaN.

In uniaxial strain the deviator is diag(s, -s/2, -s/2) with s = s_xx; von Mises equivalent stress
is 3|s|/2, and the increment of equivalent plastic strain of a radial return is (3|s|/2 - Y)/(3G).
"""

import math

from numba import njit


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
def radial_return(s_trial, flow_stress, G):
    """Return (s, d eps_p): the trial deviator scaled back onto the yield surface if outside it."""
    equivalent = 1.5 * abs(s_trial)
    if equivalent <= flow_stress:
        return s_trial, 0.0
    s = math.copysign(flow_stress / 1.5, s_trial)
    return s, (equivalent - flow_stress) / (3.0 * G)
