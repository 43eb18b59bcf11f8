"""The equation of state in the two forms users have: the hydrocode's cubic and the linear Us-up Hugoniot.

The hydrocode's Mie-Grueneisen EOS (`shockcal.hydro.eos`, Mbar, g/cc, cm/us) is
    P = c1 mu + c2 mu^2 + c3 mu^3 + gamma0 rho0 E,   mu = rho/rho0 - 1.
Shock data come as a line Us = c0 + s up (shock against particle velocity; Marsh 1980, LASL Shock
Hugoniot Data; Steinberg 1996, UCRL-MA-106439) with gamma0. Along a shock from rest the energy is
E = P (V0 - V) / 2 (Rankine-Hugoniot), so the EOS's own Hugoniot is
    P_H(mu) = (c1 mu + c2 mu^2 + c3 mu^3) / (1 - gamma0 eta / 2),   eta = 1 - V/V0 = mu / (1 + mu),
    Us = sqrt(P_H / (rho0 eta)),   up = Us eta.
`cubic_from_hugoniot` turns (c0, s, gamma0) into the cubic, `hugoniot_line` reads a cubic back as (c0, s),
both over the particle velocities of plate impact (up <= 1 km/s by default); docs/materials.md measures them.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from shockcal.errors import InputError
from shockcal.hydro.rules import check

# Particle velocities (km/s) over which the two forms are matched: plate impacts at up to 2 km/s.
UP_MAX_KM_S = 1.0
_POINTS = 200            # particle velocities of a match, evenly spaced in (0, up_max]
KM_S_TO_CM_US = 0.1

CUBIC_KEYS = ("c1_Mbar", "c2_Mbar", "c3_Mbar")
HUGONIOT_KEYS = ("c0_km_s", "s")


def cubic_from_hugoniot(rho0_g_cc: float, c0_km_s: float, s: float, gamma0: float,
                        up_max_km_s: float = UP_MAX_KM_S) -> tuple[float, float, float]:
    """The cubic (c1, c2, c3), Mbar, whose EOS Hugoniot (with the gamma0 energy term) reproduces Us = c0 + s up.

    c1 = rho0 c0^2 (the bulk sound speed is c0). c2 and c3 are the least-squares fit, in relative
    pressure, of the cold curve the line needs once the energy term is taken out:
        c1 mu + c2 mu^2 + c3 mu^3 = rho0 Us up (1 - gamma0 eta / 2),   eta = up / Us,  mu = eta / (1 - eta),
    at 200 particle velocities evenly spaced in (0, up_max_km_s]. The Taylor series of the same right-hand
    side, c2 = c1 (2s - 1 - gamma0/2), c3 = c1 (3(s-1)^2 + 2(s-1)(1 - gamma0/2)), misses the line by up to
    9.7 m/s for copper at up = 1 km/s (the fit: 0.8 m/s), and the series of the Hugoniot alone,
    rho0 c0^2 mu (1+mu) / (1-(s-1)mu)^2 (c2 = c1 (2s-1), c3 = c1 (s-1)(3s-1), the form of the LS-DYNA and
    CTH manuals, whose EOS adds a gamma0-dependent correction the hydrocode does not have) by 260-450 m/s:
    docs/materials.md.

    Args:
        rho0_g_cc: initial density (g/cc).
        c0_km_s: intercept of the Us-up line (km/s); s: its slope (-); gamma0: Grueneisen parameter (-).
        up_max_km_s: the largest particle velocity matched (km/s).
    """
    c0 = c0_km_s * KM_S_TO_CM_US
    up = np.linspace(0.0, up_max_km_s * KM_S_TO_CM_US, _POINTS + 1)[1:]
    us = c0 + s * up
    eta = up / us
    mu = eta / (1.0 - eta)
    c1 = rho0_g_cc * c0 * c0
    cold = rho0_g_cc * us * up * (1.0 - 0.5 * gamma0 * eta)
    weight = 1.0 / cold
    design = np.stack([mu**2, mu**3], axis=1) * weight[:, None]
    (c2, c3), *_ = np.linalg.lstsq(design, (cold - c1 * mu) * weight, rcond=None)
    return float(c1), float(c2), float(c3)


def hugoniot_shock_speed_km_s(up_km_s, rho0_g_cc: float, c1_Mbar: float, c2_Mbar: float, c3_Mbar: float,
                              gamma0: float) -> np.ndarray:
    """Shock speed Us (km/s) of the cubic EOS's Hugoniot from rest at particle velocities `up_km_s` (km/s):
    the eta with up = sqrt(P_H(eta) eta / rho0) found by bisection (up grows with eta on a stable
    Hugoniot), then Us = up / eta.

    Args:
        up_km_s: particle velocities (km/s), positive.
        rho0_g_cc: initial density (g/cc); c1_Mbar, c2_Mbar, c3_Mbar: the cubic (Mbar); gamma0 (-).
    """
    target = np.asarray(up_km_s, dtype=float) * KM_S_TO_CM_US

    def particle_velocity(eta):
        mu = eta / (1.0 - eta)
        pressure = mu * (c1_Mbar + mu * (c2_Mbar + mu * c3_Mbar)) / (1.0 - 0.5 * gamma0 * eta)
        return np.sqrt(pressure * eta / rho0_g_cc)

    low, high = np.zeros_like(target), np.full_like(target, 0.5)
    for _ in range(60):
        mid = 0.5 * (low + high)
        below = particle_velocity(mid) < target
        low, high = np.where(below, mid, low), np.where(below, high, mid)
    eta = 0.5 * (low + high)
    return target / eta / KM_S_TO_CM_US


def hugoniot_line(rho0_g_cc: float, c1_Mbar: float, c2_Mbar: float, c3_Mbar: float, gamma0: float,
                  up_max_km_s: float = UP_MAX_KM_S) -> tuple[float, float]:
    """A cubic EOS read as Us-up: (c0 km/s, s), the least-squares line through its Hugoniot
    (`hugoniot_shock_speed_km_s`) at 200 particle velocities evenly spaced in (0, up_max_km_s] (km/s).
    Args as `hugoniot_shock_speed_km_s`."""
    up = np.linspace(0.0, up_max_km_s, _POINTS + 1)[1:]
    s, c0 = np.polyfit(up, hugoniot_shock_speed_km_s(up, rho0_g_cc, c1_Mbar, c2_Mbar, c3_Mbar, gamma0), 1)
    return float(c0), float(s)


def cubic_eos(eos: Mapping, rho0_g_cc: float, where: str = "material.eos") -> dict[str, float]:
    """An EOS section in either form as the cubic {c1_Mbar, c2_Mbar, c3_Mbar, gamma0}: the cubic as given, or
    the Us-up Hugoniot {c0_km_s, s, gamma0} through `cubic_from_hugoniot`. Both forms at once, a form with
    a key missing, no form or a key of neither is an InputError naming `where` and the key; the values
    are checked with the hydrocode's rules (c0_km_s and s positive, gamma0 >= 0).

    Args:
        eos: the section (a mapping of the keys above).
        rho0_g_cc: initial density (g/cc), for c1 = rho0 c0^2.
        where: the section's name in messages.
    """
    unknown = sorted(set(eos) - {*CUBIC_KEYS, *HUGONIOT_KEYS, "gamma0"})
    if unknown:
        raise InputError(f"{where}.{unknown[0]}: not an EOS key; give the cubic ({', '.join(CUBIC_KEYS)}) or "
                         f"the Us-up Hugoniot ({', '.join(HUGONIOT_KEYS)}), each with gamma0")
    cubic, line = [k for k in CUBIC_KEYS if k in eos], [k for k in HUGONIOT_KEYS if k in eos]
    if cubic and line:
        raise InputError(f"{where}: {', '.join(cubic)} (the cubic) and {', '.join(line)} (the Us-up Hugoniot) "
                         "given together; give one form")
    keys = CUBIC_KEYS if cubic else HUGONIOT_KEYS
    missing = [k for k in (*keys, "gamma0") if k not in eos]
    if missing:
        form = "the cubic" if cubic else "the Us-up Hugoniot" if line else "an EOS"
        raise InputError(f"{where}.{missing[0]}: missing; {form} needs {', '.join(keys)} and gamma0"
                         + ("" if cubic or line else f" (or the cubic {', '.join(CUBIC_KEYS)} and gamma0)"))
    if cubic:
        return {k: eos[k] for k in (*CUBIC_KEYS, "gamma0")}
    for key, rule in (("c0_km_s", "positive"), ("s", "positive"), ("gamma0", "nonnegative")):
        check(f"{where}.{key}", eos[key], rule)
    density = f"{where.rsplit('.', 1)[0]}.rho0_g_cc"
    if rho0_g_cc is None:
        raise InputError(f"{density}: missing; the Us-up Hugoniot needs the density (c1 = rho0 c0^2)")
    check(density, rho0_g_cc, "positive")
    c1, c2, c3 = cubic_from_hugoniot(float(rho0_g_cc), float(eos["c0_km_s"]), float(eos["s"]), float(eos["gamma0"]))
    return {"c1_Mbar": c1, "c2_Mbar": c2, "c3_Mbar": c3, "gamma0": eos["gamma0"]}
