"""Preston-Tonks-Wallace (J. Appl. Phys. 93, 211 (2003)) as strength-law kernels.

Dimensionless: T^ = T / T_melt, tau^ = tau / G, strain rate relative to the atomic vibration rate

    xi_dot = 1/2 (4 pi rho N_A / (3 M))^(1/3) sqrt(G / rho)      (M the molar mass, so M / N_A an atom's)

Saturation and yield stresses: a thermal-activation (erf) branch and the overdriven power-law
branches, with r = epsdot / (gamma xi_dot):

    tau^_s = max(s0 - (s0 - sinf) erf(kappa T^ ln(1/r)),  s0 r^beta)
    tau^_y = max(y0 - (y0 - yinf) erf(kappa T^ ln(1/r)),  min(y1 r^y2, s0 r^beta))

Voce-like hardening, integrated at constant rate and temperature (eq. (6) of the paper):

    tau^ = tau^_s + (s0 - tau^_y)/p ln(1 - [1 - exp(-x)] exp(-p theta psi / ((s0 - tau^_y) (exp(x) - 1)))),
    x = p (tau^_s - tau^_y) / (s0 - tau^_y)
    p = 0:  tau^ = tau^_s - (tau^_s - tau^_y) exp(-theta psi / (tau^_s - tau^_y))

and the (von Mises) flow stress Y = 2 G tau^. psi is the equivalent plastic strain.

Shear modulus law used here (PTW 2003 use the same linear form in T^): G(T) = G0 (1 - alpha T / T_melt),
0 at and above T_melt; no pressure dependence (a constant T_melt and the density only through xi_dot).
Conventions: r = 0 (no strain rate) is the quasi-static limit (erf -> 1 for T > 0, power branches 0);
T = 0 gives erf(0) = 0; tau^_y >= tau^_s gives tau^ = tau^_s (no hardening; the paper's parameter
constraints, y0 < s0 and yinf < sinf, exclude it in the thermal regime). The hardening is evaluated
with expm1/log1p so that small p stays accurate.
"""

from __future__ import annotations

import math
from typing import NamedTuple

from numba import njit

AVOGADRO = 6.02214076e23   # 1/mol


class PrestonTonksWallace(NamedTuple):
    """PTW parameters and its shear-modulus law in code units."""

    theta: float           # hardening rate at the yield stress, - (over G)
    p: float               # -
    s0: float              # -
    sinf: float            # -
    kappa: float           # -
    gamma: float           # -
    y0: float              # -
    yinf: float            # -
    y1: float              # -
    y2: float              # -
    beta: float            # -
    M: float               # molar mass, g/mol
    rho0: float            # g/cc
    G0: float              # Mbar
    alpha: float           # -
    T_melt: float          # K


@njit(cache=True, error_model="numpy")
def ptw_shear_modulus(law, P, T, eta):
    """G(T) = G0 (1 - alpha T / T_melt) (Mbar), 0 at and above T_melt; `P`, `eta` not used."""
    if T >= law.T_melt:
        return 0.0
    return max(law.G0 * (1.0 - law.alpha * T / law.T_melt), 0.0)


@njit(cache=True, error_model="numpy")
def ptw_vibration_rate(law, G, eta):
    """xi_dot = 1/2 (4 pi rho N_A / (3 M))^(1/3) sqrt(G / rho) (1/us with G in Mbar, rho in g/cc)."""
    rho = law.rho0 * eta
    return 0.5 * (4.0 * math.pi * rho * AVOGADRO / (3.0 * law.M)) ** (1.0 / 3.0) * math.sqrt(G / rho)


@njit(cache=True, error_model="numpy")
def ptw_rate_ratio(law, G, strain_rate, eta):
    """r = epsdot / (gamma xi_dot) at equivalent strain rate `strain_rate` (1/us), shear modulus G (Mbar)."""
    return strain_rate / (law.gamma * ptw_vibration_rate(law, G, eta))


@njit(cache=True, error_model="numpy")
def ptw_hardened(law, tau_s, tau_y, eps_p):
    """tau^ at equivalent plastic strain `eps_p` between the yield `tau_y` and saturation `tau_s` stresses
    (over G): eq. (6), tau_s when tau_y >= tau_s."""
    spread = tau_s - tau_y
    if spread <= 0.0:
        return tau_s
    if law.p == 0.0:
        return tau_s - spread * math.exp(-law.theta * eps_p / spread)
    scale = law.s0 - tau_y
    x = law.p * spread / scale
    return tau_s + scale / law.p * math.log1p(
        math.expm1(-x) * math.exp(-law.p * law.theta * eps_p / (scale * math.expm1(x))))


@njit(cache=True, error_model="numpy")
def ptw_tau(law, r, T, eps_p):
    """tau^ (over G) at rate ratio `r`, temperature `T` (K) and equivalent plastic strain `eps_p`."""
    T_hat = T / law.T_melt
    if T_hat <= 0.0:
        thermal = 0.0
    elif r > 0.0:
        thermal = math.erf(law.kappa * T_hat * -math.log(r))
    else:
        thermal = 1.0
    power_s = law.s0 * r ** law.beta
    tau_s = max(law.s0 - (law.s0 - law.sinf) * thermal, power_s)
    tau_y = max(law.y0 - (law.y0 - law.yinf) * thermal, min(law.y1 * r ** law.y2, power_s))
    return ptw_hardened(law, tau_s, tau_y, eps_p)


@njit(cache=True, error_model="numpy")
def ptw_flow_stress_at(law, G, eps_p, strain_rate, T, P, eta):
    """Flow stress (Mbar) at equivalent plastic strain `eps_p`, equivalent strain rate `strain_rate`
    (1/us), temperature `T` (K) and density ratio `eta`, where the shear modulus is `G` (Mbar, the law's
    G(T)); `P` not used."""
    if G <= 0.0:
        return 0.0
    return 2.0 * G * ptw_tau(law, ptw_rate_ratio(law, G, strain_rate, eta), T, eps_p)


@njit(cache=True, error_model="numpy")
def ptw_flow_stress(law, eps_p, strain_rate, T, P, eta):
    """Flow stress (Mbar) at equivalent plastic strain `eps_p`, equivalent strain rate `strain_rate`
    (1/us), temperature `T` (K) and density ratio `eta` (through rho in xi_dot); `P` not used."""
    return ptw_flow_stress_at(law, ptw_shear_modulus(law, P, T, eta), eps_p, strain_rate, T, P, eta)


# Floor: a lower bound of the flow stress that lets the solver skip it in provably elastic cells (exact).
# Quasi-static: tau^ >= its value at r = 0 (tau_s = sinf, tau_y = yinf) at the same eps_p, for every r.
# At any r, thermal <= 1 = its value at r = 0, so tau_s >= sinf and tau_y >= yinf (s0 > sinf, y0 > yinf;
# the power branches only raise them). Eq. (6) solves dtau/dpsi = theta (exp(k (tau_s - tau)) - 1) /
# (exp(k (tau_s - tau_y)) - 1), tau(0) = tau_y, k = p / (s0 - tau_y), theta >= 0. It does not fall as
# tau_s rises: d tau / d tau_s = 1 - exp(-w) (exp(-x) + w) / (1 - (1 - exp(-x)) exp(-w)) >= 0, since
# w exp(-w) <= 1 - exp(-w) (x = k (tau_s - tau_y), w = k theta psi / (exp(x) - 1)). Nor as tau_y rises
# while tau_s <= s0: the start rises, and the right-hand side grows with k while k (tau_s - tau_y)
# falls. So raise tau_y from yinf at tau_s = sinf <= s0, then tau_s; tau_y >= tau_s gives tau_s, above
# every value below it; tau_y >= s0 (only for r > 1) gives tau^ >= min(tau_s, tau_y) >= s0.


@njit(cache=True, error_model="numpy")
def ptw_floors_hold(law):
    """Whether the floor's monotonicity holds: theta, kappa, beta, y2 >= 0 (the boxes' values)."""
    return law.theta >= 0.0 and law.kappa >= 0.0 and law.beta >= 0.0 and law.y2 >= 0.0


@njit(cache=True, error_model="numpy")
def ptw_hardening(law, eps_p):
    """tau^ (over G) at `eps_p` in the quasi-static limit (r = 0: tau_s = sinf, tau_y = yinf), the cell's
    cached hardening; -1 where the floor does not hold."""
    return ptw_hardened(law, law.sinf, law.yinf, eps_p) if ptw_floors_hold(law) else -1.0


@njit(cache=True, error_model="numpy")
def ptw_flow_stress_floor(law, hard, G, T, eta, flow_floor, floor_hotter, floor_T):
    """A lower bound (Mbar) of the flow stress at any strain rate, at shear modulus G (Mbar): 2 G `hard`, the
    quasi-static tau^; -1 (none) where the floor does not hold. Nothing remembered is used."""
    return -1.0 if hard < 0.0 else 2.0 * G * hard
