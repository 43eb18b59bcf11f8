"""Mie-Grueneisen equation of state with a cubic cold curve (SPEC section 2).

Units: Mbar, g/cc, (cm/us)^2 per gram for specific internal energy E. mu = rho/rho0 - 1.
    P = c1 mu + c2 mu^2 + c3 mu^3 + gamma0 rho0 E
The same polynomial is used in tension (mu < 0), as the paper's table gives it.
"""

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
