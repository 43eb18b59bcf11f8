"""Mie-Grueneisen equation of state with a cubic cold curve (SPEC section 2).

Units: Mbar, g/cc, (cm/us)^2 per gram for specific internal energy E. mu = rho/rho0 - 1.
    P = c1 mu + c2 mu^2 + c3 mu^3 + gamma0 rho0 E
The same polynomial is used in tension (mu < 0), as the paper's table gives it.
"""

import numpy as np
from numba import njit


@njit(cache=True, error_model="numpy")
def cold_pressure(mu, c1, c2, c3):
    """The mu-dependent part of P (Mbar)."""
    return mu * (c1 + mu * (c2 + mu * c3))


@njit(cache=True, error_model="numpy")
def bulk_sound_speed_sq(mu, pressure, volume, rho0, c1, c2, c3, gamma0):
    """Isentropic (dP/drho)_s = dP/dmu / rho0 + gamma0 rho0 P / rho^2 (volume = 1/rho), in (cm/us)^2."""
    dp_dmu = c1 + mu * (2.0 * c2 + 3.0 * c3 * mu)
    return dp_dmu / rho0 + gamma0 * rho0 * pressure * volume * volume


def zero_pressure_compression(E, rho0, c1, c2, c3, gamma0) -> float:
    """mu0 at which a material of specific internal energy E is at zero pressure:
    c1 mu0 + c2 mu0^2 + c3 mu0^3 + gamma0 rho0 E = 0, the real root nearest 0 (mu0 < 0 for E > 0: a
    hot plate expands), polished by Newton steps to the rounding of P. E = 0 gives mu0 = 0 exactly.

    Args:
        E: specific internal energy ((cm/us)^2).
        rho0: reference density (g/cc); c1, c2, c3: cold-curve coefficients (Mbar); gamma0: (-).
    """
    if E == 0.0:
        return 0.0
    thermal = gamma0 * rho0 * E
    roots = np.roots([c3, c2, c1, thermal])
    real = roots[np.abs(roots.imag) <= 1e-9 * max(1.0, float(np.max(np.abs(roots))))].real
    if real.size == 0:
        raise ValueError(f"no real zero-pressure compression for E = {E} (cm/us)^2")
    mu = float(real[np.argmin(np.abs(real))])
    for _ in range(3):
        mu -= (cold_pressure(mu, c1, c2, c3) + thermal) / (c1 + mu * (2.0 * c2 + 3.0 * c3 * mu))
    return mu
