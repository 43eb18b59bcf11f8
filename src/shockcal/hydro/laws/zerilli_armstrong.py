"""Zerilli-Armstrong for fcc metals (J. Appl. Phys. 61, 1816 (1987)) as a strength-law kernel.

    sigma = C0 + C2 sqrt(eps_p) exp(-C3 T + C4 T ln(epsdot / epsdot_0))

C0 (= Delta sigma'_G + k l^(-1/2) of the paper: athermal stress plus grain-size term) and C2 are stresses,
C3 and C4 in 1/K, T the absolute temperature; epsdot_0 = 1 /s reproduces the paper's ln(epsdot) with
epsdot in 1/s. The rate is not floored (ln < 0 below epsdot_0 is the model's thermal activation);
epsdot = 0 is the quasi-static limit, sigma = C0 when C4 T > 0. No melt cut-off (the 1987 form has none).
"""

from __future__ import annotations

import math
from typing import NamedTuple

from numba import njit


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
