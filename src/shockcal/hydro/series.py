"""Powers and exponentials after a small change, by truncated series whose remainder lies below rounding.

A cell that stays plastic changes its plastic strain, temperature and plastic rate by a small fraction each
step; the return needs eps_p^n, T*^m and e^x at the new values. From the values at the old ones:

    e^(x + s)     = e^x (1 + s + s^2/2 + ... + s^6/6!),                        |s| <= EXP_STEP_MAX
    (a (1 + u))^m = a^m (1 + c1 u + c2 u^2 + ... + c5 u^5),  c_k = binom(m, k),  while |c6 u^6| <= REMAINDER

(each the Taylor series, its first omitted term below REMAINDER, about a tenth of the rounding of a number
near 1). Where the series would not hold, the caller evaluates the power or exponential itself.
"""

from __future__ import annotations

from numba import njit

REMAINDER = 1e-17          # the first omitted term of a series, relative: a tenth of the rounding of 1
EXP_STEP_MAX = 1e-2        # |s| up to which e^s's series to s^6 holds: s^7 / 7! = 2e-18
NO_SERIES = -2.0           # what `power_growth` returns where its series does not hold ((1 + u)^m - 1 > -1)
INVERSE_INTEGER = (1.0, 1.0, 0.5, 1.0 / 3.0, 0.25, 0.2, 1.0 / 6.0)             # 1/k: multiplied, not divided
INVERSE_FACTORIAL = (1.0, 1.0, 0.5, 1.0 / 6.0, 1.0 / 24.0, 1.0 / 120.0, 1.0 / 720.0)   # 1/k!


@njit(cache=True, error_model="numpy")
def exp_small(s):
    """e^s (|s| <= EXP_STEP_MAX) by its Taylor series to s^6, grouped in powers of s^2 (Estrin's scheme: a
    short chain of dependent operations, which is what a plastic cell's solve waits on)."""
    s2 = s * s
    return (1.0 + s) + s2 * ((INVERSE_FACTORIAL[2] + s * INVERSE_FACTORIAL[3])
                             + s2 * ((INVERSE_FACTORIAL[4] + s * INVERSE_FACTORIAL[5]) + s2 * INVERSE_FACTORIAL[6]))


@njit(cache=True, error_model="numpy")
def power_growth(u, m):
    """(1 + u)^m - 1 by the binomial series to u^5, or NO_SERIES where its first omitted term,
    binom(m, 6) u^6, would exceed REMAINDER (the caller then evaluates the power). Grouped as `exp_small`."""
    c2 = m * (m - 1.0) * INVERSE_INTEGER[2]
    c3 = c2 * (m - 2.0) * INVERSE_INTEGER[3]
    c4 = c3 * (m - 3.0) * INVERSE_INTEGER[4]
    c5 = c4 * (m - 4.0) * INVERSE_INTEGER[5]
    c6 = c5 * (m - 5.0) * INVERSE_INTEGER[6]
    u2 = u * u
    u4 = u2 * u2
    if not abs(c6) * u4 * u2 <= REMAINDER:
        return NO_SERIES
    return (m * u + u2 * (c2 + u * c3)) + u4 * (c4 + u * c5)
