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
def ptw_rate_ratio_sixth(law, G, strain_rate, eta):
    """r^6 without a root: r = epsdot eta^(1/6) / (K sqrt(G)), K = gamma / 2 (4 pi rho0 N_A / (3 M))^(1/3) / sqrt(rho0),
    so r^6 = epsdot^6 eta / (K^6 G^3), K^6 = gamma^6 / 64 (4 pi rho0 N_A / (3 M))^2 / rho0^3."""
    k_sixth = law.gamma ** 6 / 64.0 * (4.0 * math.pi * law.rho0 * AVOGADRO / (3.0 * law.M)) ** 2 / law.rho0 ** 3
    rate_cubed = strain_rate * strain_rate * strain_rate
    return rate_cubed * rate_cubed * eta / (k_sixth * G * G * G)


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


# Floors: lower bounds of the flow stress that let the solver skip it in provably elastic cells (exact).
# 1. Quasi-static: tau^ >= its value at r = 0 (tau_s = sinf, tau_y = yinf) at the same eps_p, for every r.
#    At any r, thermal <= 1 = its value at r = 0, so tau_s >= sinf and tau_y >= yinf (s0 > sinf, y0 > yinf;
#    the power branches only raise them). Eq. (6) solves dtau/dpsi = theta (exp(k (tau_s - tau)) - 1) /
#    (exp(k (tau_s - tau_y)) - 1), tau(0) = tau_y, k = p / (s0 - tau_y), theta >= 0. It does not fall as
#    tau_s rises: d tau / d tau_s = 1 - exp(-w) (exp(-x) + w) / (1 - (1 - exp(-x)) exp(-w)) >= 0, since
#    w exp(-w) <= 1 - exp(-w) (x = k (tau_s - tau_y), w = k theta psi / (exp(x) - 1)). Nor as tau_y rises
#    while tau_s <= s0: the start rises, and the right-hand side grows with k while k (tau_s - tau_y)
#    falls. So raise tau_y from yinf at tau_s = sinf <= s0, then tau_s; tau_y >= tau_s gives tau_s, above
#    every value below it; tau_y >= s0 (only for r > 1) gives tau^ >= min(tau_s, tau_y) >= s0.
# 2. Remembered: for r <= 1 (log(1/r) >= 0) and kappa, beta, y2 >= 0, tau_s and tau_y do not fall as r
#    rises or as T falls, so tau^ at (r, T, eps_p) is at least its value at any (r_f <= r, T_f >= T,
#    eps_p_f <= eps_p). After a full evaluation finds a cell elastic, it remembers tau^ at
#    r_f = r PTW_FLOOR_RATE_FACTOR and T_f = T + PTW_FLOOR_MARGIN_K (the cell's flow_floor, floor_hotter
#    and floor_T slots: tau^, r_f^6, T_f); the floor holds while r_f <= r <= 1 and T <= T_f (eps_p only
#    grows), checked on r^6, which needs no root (`ptw_rate_ratio_sixth`).
PTW_FLOOR_RATE_FACTOR = math.exp(-0.5)   # measured best of e^-0.1 .. e^-3 on 105S posterior runs
PTW_FLOOR_MARGIN_K = 1.0                 # measured best of 0.2 .. 10 K


@njit(cache=True, error_model="numpy")
def ptw_floors_hold(law):
    """Whether the floors' monotonicity holds: theta, kappa, beta, y2 >= 0 (the boxes' values)."""
    return law.theta >= 0.0 and law.kappa >= 0.0 and law.beta >= 0.0 and law.y2 >= 0.0


@njit(cache=True, error_model="numpy")
def ptw_hardening(law, eps_p):
    """tau^ (over G) at `eps_p` in the quasi-static limit (r = 0: tau_s = sinf, tau_y = yinf), the cell's
    cached hardening; -1 where the floors do not hold."""
    return ptw_hardened(law, law.sinf, law.yinf, eps_p) if ptw_floors_hold(law) else -1.0


@njit(cache=True, error_model="numpy")
def ptw_flow_stress_floor(law, hard, G, strain_rate, T, eta, flow_floor, floor_hotter, floor_T):
    """A lower bound (Mbar) of the flow stress at shear modulus G (Mbar), equivalent strain rate (1/us),
    temperature T (K) and eta: 2 G times the cell's remembered tau^ `flow_floor` while it holds (r^6
    from `floor_hotter` to 1, T <= `floor_T`), else 2 G `hard`, the quasi-static tau^; -1 (none)
    where the floors do not hold."""
    if hard < 0.0:
        return -1.0
    if flow_floor > hard and T <= floor_T and floor_hotter <= ptw_rate_ratio_sixth(law, G, strain_rate, eta) <= 1.0:
        return 2.0 * G * flow_floor
    return 2.0 * G * hard


@njit(cache=True, error_model="numpy")
def ptw_remember_floor(law, G, eps_p, strain_rate, T, eta, flow_floor, floor_hotter, floor_T):
    """The cell's remembered floor after a full evaluation found it elastic: (tau^ at r_f and T_f, r_f^6,
    T_f) with r_f = r PTW_FLOOR_RATE_FACTOR, T_f = T + PTW_FLOOR_MARGIN_K; the old one kept where none
    can be set (r > 1, or the floors do not hold)."""
    r = ptw_rate_ratio(law, G, strain_rate, eta)
    if r > 1.0 or not ptw_floors_hold(law):
        return flow_floor, floor_hotter, floor_T
    r_floor, T_floor = r * PTW_FLOOR_RATE_FACTOR, T + PTW_FLOOR_MARGIN_K
    return ptw_tau(law, r_floor, T_floor, eps_p), r_floor ** 6, T_floor
