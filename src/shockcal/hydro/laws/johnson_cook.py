"""Johnson-Cook (1983) as a strength-law kernel: a thin wrapper over today's `hydro.strength` functions.

    Y = (A + B eps_p^n) (1 + C ln(epsdot / epsdot_0)) (1 - T*^m),   T* = (T - T_ref) / (T_melt - T_ref)

with the project's conventions (docs/hydro.md, `hydro/strength.py`): the rate ratio floored at 1,
n = 0 meaning eps_p^0 = 1, no softening at T* <= 0 and none left at T* >= 1. The kernel calls
`hardening`, `rate_factor` and `thermal_factor` in the order `hydro.strength.flow_stress` uses, so
it equals the hydrocode's Johnson-Cook flow stress bit for bit (tests/test_strength_laws.py).
"""

from __future__ import annotations

from typing import NamedTuple

from numba import njit

from shockcal.hydro.strength import hardening, rate_factor, thermal_factor


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
    homologous = (T - law.T_ref) * (1.0 / (law.T_melt - law.T_ref))
    return (hardening(law.A, law.B, law.n, eps_p) * rate_factor(law.C, strain_rate, law.rate_ref)
            * thermal_factor(law.m, homologous))
