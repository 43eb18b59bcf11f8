"""Steinberg-Guinan (Steinberg, Cochran, Guinan, J. Appl. Phys. 51, 1498 (1980)) as strength-law kernels.

    Y   = min(Y0 [1 + beta (eps_p + eps_i)]^n, Ymax) G(P, T, eta) / G0
    G   = G0 [1 + (G'_P / G0) P eta^(-1/3) + (G'_T / G0) (T - 300 K)],   0 at and above T_melt(eta)
    T_melt(eta) = T_m0 exp(2 a (1 - 1/eta)) eta^(2 (gamma0 - a - 1/3))

eta = rho / rho0 (compression ratio), P the pressure (positive in compression). G'_P = dG/dP is
dimensionless, G'_T / G0 = (dG/dT) / G0 in 1/K (negative: G falls as T rises). The rate-independent
form of 1980 (no thermally activated term, as in Steinberg's 1996 tables). A negative G (far above
the table's range) is clipped at 0, so Y is never negative.
"""

from __future__ import annotations

import math
from typing import NamedTuple

from numba import njit

SG_T_REF_K = 300.0        # the temperature G0 refers to in the 1980 paper


class SteinbergGuinan(NamedTuple):
    """Steinberg-Guinan parameters in code units."""

    Y0: float              # Mbar
    Ymax: float            # Mbar
    beta: float            # -
    n: float               # -
    eps_i: float           # initial equivalent plastic strain, -
    G0: float              # Mbar
    dGdP: float            # G'_P, -
    dGdT_over_G0: float    # G'_T / G0, 1/K
    T_m0: float            # K
    gamma0: float          # -
    a: float               # -


@njit(cache=True, error_model="numpy")
def steinberg_guinan_melt_temperature(law, eta):
    """T_melt(eta) = T_m0 exp(2 a (1 - 1/eta)) eta^(2 (gamma0 - a - 1/3)) (K)."""
    return law.T_m0 * math.exp(2.0 * law.a * (1.0 - 1.0 / eta)) * eta ** (2.0 * (law.gamma0 - law.a - 1.0 / 3.0))


@njit(cache=True, error_model="numpy")
def steinberg_guinan_melt_temperature_below(law, eta):
    """A lower bound (K) of T_melt(eta) without exp or pow: T_melt = T_m0 exp(E), E = 2 a (1 - 1/eta)
    + c ln(eta), c = 2 (gamma0 - a - 1/3); ln(eta) lies between 1 - 1/eta and eta - 1, and exp(E) >= 1 + E.
    Lowered by 1e-12 of itself, far above the rounding of either side."""
    c = 2.0 * (law.gamma0 - law.a - 1.0 / 3.0)
    log_eta_times_c = c * (1.0 - 1.0 / eta) if c >= 0.0 else c * (eta - 1.0)
    return law.T_m0 * (1.0 + 2.0 * law.a * (1.0 - 1.0 / eta) + log_eta_times_c) * (1.0 - 1e-12)


@njit(cache=True, error_model="numpy")
def steinberg_guinan_shear_modulus(law, P, T, eta):
    """G(P, T, eta) (Mbar) at pressure `P` (Mbar), temperature `T` (K) and density ratio `eta`; the melt
    law is evaluated only where T reaches its cheap lower bound."""
    if T >= steinberg_guinan_melt_temperature_below(law, eta) and T >= steinberg_guinan_melt_temperature(law, eta):
        return 0.0
    G = law.G0 * (1.0 + (law.dGdP / law.G0) * P * eta ** (-1.0 / 3.0) + law.dGdT_over_G0 * (T - SG_T_REF_K))
    return max(G, 0.0)


@njit(cache=True, error_model="numpy")
def steinberg_guinan_hardening(law, eps_p):
    """min(Y0 [1 + beta (eps_p + eps_i)]^n, Ymax) (Mbar): the yield stress at G = G0."""
    return min(law.Y0 * (1.0 + law.beta * (eps_p + law.eps_i)) ** law.n, law.Ymax)


@njit(cache=True, error_model="numpy")
def steinberg_guinan_flow_stress_at(law, G, eps_p, strain_rate, T, P, eta):
    """Flow stress (Mbar) at equivalent plastic strain `eps_p` where the shear modulus is `G` (Mbar, the
    law's G(P, T, eta)); `strain_rate`, `T`, `P` and `eta` enter only through G."""
    return steinberg_guinan_hardening(law, eps_p) * G / law.G0


@njit(cache=True, error_model="numpy")
def steinberg_guinan_flow_stress(law, eps_p, strain_rate, T, P, eta):
    """Flow stress (Mbar) at equivalent plastic strain `eps_p`, temperature `T` (K), pressure `P`
    (Mbar) and density ratio `eta`; `strain_rate` (1/us) is not used (rate-independent form)."""
    return steinberg_guinan_flow_stress_at(law, steinberg_guinan_shear_modulus(law, P, T, eta), eps_p, strain_rate,
                                           T, P, eta)


@njit(cache=True, error_model="numpy")
def steinberg_guinan_flow_stress_floor(law, hard, G, T, eta, flow_floor, floor_hotter, floor_T):
    """The flow stress itself (Mbar) from the cell's cached `steinberg_guinan_hardening` and its G (Mbar):
    the law has no rate term, so its floor is exact and nothing is remembered."""
    return hard * G / law.G0
