"""Zerilli-Armstrong for fcc metals (J. Appl. Phys. 61, 1816 (1987)) as a strength-law kernel.

    sigma = C0 + C2 sqrt(eps_p) exp(-C3 T + C4 T ln(epsdot / epsdot_0))

C0 (= Delta sigma'_G + k l^(-1/2) of the paper: athermal stress plus grain-size term) and C2 are stresses,
C3 and C4 in 1/K, T the absolute temperature; epsdot_0 = 1 /s reproduces the paper's ln(epsdot) with
epsdot in 1/s. The rate is not floored (ln < 0 below epsdot_0 is the model's thermal activation);
epsdot = 0 is the quasi-static limit, sigma = C0 when C4 T > 0. No melt cut-off (the 1987 form has none).

The consistent return (`zerilli_armstrong_plastic_increment`) in closed form up to one scalar equation:
with K = C2 sqrt(eps_p) exp(-C3 T) at the step's start, p = C4 T and d_ref = dt epsdot_0, the increment
d = d_ref e^z solves

    3/2 |s_trial| - C0 - 3 G d_ref e^z = K e^(p z),

whose residual falls with z and is concave: Newton steps from an upper bound of the root (each term alone)
approach it from above.
"""

from __future__ import annotations

import math
from typing import NamedTuple

from numba import njit

NEWTON_STEP_STOP = 1e-9    # a Newton step in z this small leaves an error below 1e-17 (quadratic convergence)
NEWTON_MAX_STEPS = 100


class ZerilliArmstrong(NamedTuple):
    """Zerilli-Armstrong fcc parameters in code units."""

    C0: float              # Mbar
    C2: float              # Mbar
    C3: float              # 1/K
    C4: float              # 1/K
    rate_ref: float        # 1/us


@njit(cache=True, error_model="numpy")
def zerilli_armstrong_flow_stress(law, eps_p, strain_rate, T, P, eta):
    """Flow stress (Mbar) at equivalent plastic strain `eps_p`, equivalent strain rate `strain_rate`
    (1/us) and temperature `T` (K); `P` and `eta` are not used."""
    if strain_rate > 0.0:
        exponent = -law.C3 * T + law.C4 * T * math.log(strain_rate / law.rate_ref)
    elif law.C4 * T > 0.0:
        return law.C0
    else:
        exponent = -law.C3 * T
    return law.C0 + law.C2 * math.sqrt(eps_p) * math.exp(exponent)


@njit(cache=True, error_model="numpy")
def zerilli_armstrong_flow_stress_floor(law, hard, G, T, eta, flow_floor, floor_hotter, floor_T):
    """C0 (Mbar), a lower bound of the flow stress at any strain, rate and temperature when C2 >= 0
    (the exponential is positive); -1 (none) otherwise. Nothing cached or remembered is used."""
    return law.C0 if law.C2 >= 0.0 else -1.0


@njit(cache=True, error_model="numpy")
def zerilli_armstrong_plastic_increment(law, equivalent, rate_free, G, dt, hard, eps_p, T, P, eta):
    """The consistent return's plastic strain increment d and the flow stress Y (Mbar) at the step's plastic
    rate d / dt (module docstring), for a trial von Mises stress `equivalent` (Mbar) above the rate-free flow
    stress `rate_free` (Mbar), shear modulus G (Mbar), time step dt (us), plastic strain eps_p and
    temperature T (K) at the step's start. Without a rate term (C4 T <= 0) or without hardening (eps_p = 0)
    the radial return onto `rate_free`."""
    exponent, scale = law.C4 * T, law.C2 * math.sqrt(eps_p) * math.exp(-law.C3 * T)     # p and K
    overstress, three_G = equivalent - rate_free, 3.0 * G
    if exponent <= 0.0 or scale <= 0.0:
        return overstress / three_G, rate_free
    d_ref = dt * law.rate_ref
    elastic_ref = three_G * d_ref                                  # 3 G d at z = 0
    z = min(math.log(overstress / elastic_ref), math.log(overstress / scale) / exponent)
    for _ in range(NEWTON_MAX_STEPS):
        elastic, hardening = elastic_ref * math.exp(z), scale * math.exp(exponent * z)
        step = (overstress - elastic - hardening) / (elastic + exponent * hardening)
        z += step
        if -step <= NEWTON_STEP_STOP:
            break
    return d_ref * math.exp(z), law.C0 + scale * math.exp(exponent * z)
