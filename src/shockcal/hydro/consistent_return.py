"""The rate-dependent return solved consistently: backward Euler on the equivalent plastic strain.

In a plastic step of length dt the increment d > 0 of equivalent plastic strain solves

    3/2 |s_trial| - 3 G d = Y(eps_p, d / dt, T, P, eta),

the flow stress at the plastic strain rate of the step being solved: the radial return of Wilkins (1964)
made implicit in the rate (Simo & Hughes 1998, Computational Inelasticity, sec. 3.3 and 3.7, the
viscoplastic return; Ponthot 2002, Int. J. Plasticity 18, 91, for rate-dependent laws such as
Johnson-Cook). The hardening is read at the step's start, as the rate-free radial return reads it, so a
law without a rate term (or C = 0) returns exactly as that return does; the rate, the stiff term, is
implicit. The returned deviator is s = sign(s_trial) Y / (3/2), on the yield surface at the step's plastic
rate.

`law_plastic_increment` picks, when numba compiles: the law's own solution where it declares one
(`Law.plastic_increment`: Johnson-Cook's and Zerilli-Armstrong's closed forms), the radial return for a rate-free law
(Steinberg-Guinan, bit for bit as before), else `bracketed_plastic_increment`, which any law's kernel
serves.

`law_plastic_increment_warm` is the same with the cell's warm start (x_warm, rate_warm: the law's solve
variable and the plastic rate, 1/us, at the cell's last plastic step) in and renewed, for a law that declares
`plastic_increment_warm` (Johnson-Cook: x = ln(rate / epsdot_0)) and for the bracketed iteration (x_warm: the
secant slope dY / d ln d, Mbar, `bracketed_plastic_increment_warm`); other laws pass it through.

`bracketed_plastic_increment`: the residual r(d) = 3/2 |s_trial| - 3 G d - Y(d) falls strictly with d (Y
does not fall as the plastic rate grows). At d = 0 the plastic rate is 0, where each law reads its own limit
(PTW's quasi-static r = 0), so r(0) > 0 for a plastic trial; at the rate-free
return's increment r <= 0. The root is bracketed there and found by Newton steps in ln d, where the rate
terms are close to linear, the slope of Y a secant through the last two iterates (a law need not supply
one); a step that leaves the bracket is replaced by a bisection (in ln d once the bracket's lower end is
positive). A Newton step inside the bracket that moves ln d by at most LAST_STEP is the last: its d is returned
with Y to first order (Y + slope x step, no further evaluation of the law; the neglected terms are of order
step^2 and (slope error) x step: at most 7e-16 of the law's Y at the returned d over tests/test_rate_return.py's
PTW cells), which saves the evaluations that converged a step of 1e-8 to 1e-14 (docs/hydro.md, "Speed"). A
bisection step is never the last: it stops when a step would move d by at most RELATIVE_TOLERANCE of d, or
after MAX_ITERATIONS. Until the bracket has a positive lower end a bisection halves d, and a root far below the
bracket's top takes as many halvings as its binary orders of magnitude: at 60 iterations some steps of PTW runs
stopped unconverged, each a jump (a 1e-12 change of an input moved a 104S-like run's trace by up to 0.6 m/s); at
200 none did (48 perturbed runs, docs/hydro.md).
"""

from __future__ import annotations

import math

from numba import njit
from numba.extending import overload

from shockcal.hydro.laws.kernels import declared_law, law_flow_stress_cached

RELATIVE_TOLERANCE = 1e-14
LAST_STEP = 1e-8          # a Newton step in ln d this small is the last (module docstring)
MAX_ITERATIONS = 200       # with no positive lower end the bisection halves d: 200 halvings reach 1e-60 of it


@njit(cache=True, error_model="numpy")
def bracketed_plastic_increment(law, equivalent, rate_free, G, dt, hard, eps_p, T, P, eta):
    """The plastic strain increment d and the flow stress Y (Mbar) at the step's plastic rate d / dt for a trial
    von Mises stress `equivalent` (Mbar) above the rate-free flow stress `rate_free` (Mbar), shear modulus G
    (Mbar), step dt (us), at the cell's cached hardening `hard`, plastic strain eps_p, temperature T (K),
    pressure P (Mbar) and density ratio eta (module docstring); without a warm start."""
    d, Y, _, _ = bracketed_plastic_increment_warm(law, equivalent, rate_free, G, dt, hard, eps_p, T, P, eta, 0.0, 0.0)
    return d, Y


@njit(cache=True, error_model="numpy")
def bracketed_plastic_increment_warm(law, equivalent, rate_free, G, dt, hard, eps_p, T, P, eta, slope_warm,
                                     rate_warm):
    """`bracketed_plastic_increment`'s (d, Y) and the cell's renewed warm start (the secant slope dY / d ln d,
    Mbar, and the plastic rate d / dt, 1/us, at the solution). With a warm start (rate_warm, 1/us, inside the
    bracket and slope_warm > 0) the iteration starts at d = rate_warm dt with a Newton step on the remembered
    slope, the bracket [0, rate-free increment] kept; else at the bracket's upper end, as without one."""
    three_G = 3.0 * G
    lo, hi = 0.0, (equivalent - rate_free) / three_G
    d_prev, warm = rate_warm * dt, rate_warm > 0.0 and slope_warm > 0.0
    if not (warm and d_prev < hi):
        d_prev, warm = hi, False
    Y_prev = law_flow_stress_cached(law, hard, G, eps_p, d_prev / dt, T, P, eta)
    if warm:
        r = equivalent - three_G * d_prev - Y_prev
        if r > 0.0:
            lo = d_prev
        else:
            hi = d_prev
        step = r / (three_G * d_prev + slope_warm)                       # Newton in ln d, the remembered slope
        d = d_prev * math.exp(step)
        if lo < d < hi and abs(step) <= LAST_STEP:                       # the warm start's step is the last
            return d, Y_prev + slope_warm * step, slope_warm, d / dt
        if not lo < d < hi:
            d = math.sqrt(lo * hi) if lo > 0.0 else 0.5 * hi
    elif Y_prev <= rate_free:    # the flow stress did not rise over the bracket: the rate-free return
        return d_prev, rate_free, slope_warm, rate_warm
    else:
        d = hi * (equivalent - rate_free) / (Y_prev - rate_free + equivalent - rate_free)   # regula falsi on [0, hi]
    x_prev = math.log(d_prev)
    for _ in range(MAX_ITERATIONS):
        Y = law_flow_stress_cached(law, hard, G, eps_p, d / dt, T, P, eta)
        r = equivalent - three_G * d - Y
        x = math.log(d)
        secant = (Y - Y_prev) / (x - x_prev)                    # Y's slope in ln d
        if r == 0.0:
            return d, Y, secant, d / dt
        if r > 0.0:
            lo = d
        else:
            hi = d
        step = r / (three_G * d + secant)                       # Newton in ln d: dr / d ln d = -(3 G d + secant)
        candidate = d * math.exp(step)
        if lo < candidate < hi and abs(step) <= LAST_STEP:      # the last step: Y to first order, no evaluation
            return candidate, Y + secant * step, secant, candidate / dt
        if not lo < candidate < hi:
            candidate = math.sqrt(lo * hi) if lo > 0.0 else 0.5 * hi
        if abs(candidate - d) <= RELATIVE_TOLERANCE * d:
            return d, Y, secant, d / dt
        x_prev, Y_prev, d = x, Y, candidate
    return d, law_flow_stress_cached(law, hard, G, eps_p, d / dt, T, P, eta), slope_warm, rate_warm


def law_plastic_increment(law, equivalent, rate_free, G, dt, hard, eps_p, T, P, eta):
    """The consistent return's (d, Y) for the law whose parameters `law` holds (arguments as in
    `bracketed_plastic_increment`)."""
    declared = declared_law(type(law))
    if declared.plastic_increment is not None:
        return declared.plastic_increment(law, equivalent, rate_free, G, dt, hard, eps_p, T, P, eta)
    if not declared.rate_dependent:
        return (equivalent - rate_free) / (3.0 * G), rate_free
    return bracketed_plastic_increment(law, equivalent, rate_free, G, dt, hard, eps_p, T, P, eta)


@overload(law_plastic_increment, jit_options={"cache": True})
def _law_plastic_increment(law, equivalent, rate_free, G, dt, hard, eps_p, T, P, eta):
    declared = declared_law(law)
    if declared.plastic_increment is not None:
        kernel = declared.plastic_increment
        return lambda law, equivalent, rate_free, G, dt, hard, eps_p, T, P, eta: kernel(law, equivalent, rate_free,
                                                                                         G, dt, hard, eps_p, T, P, eta)
    if not declared.rate_dependent:
        return lambda law, equivalent, rate_free, G, dt, hard, eps_p, T, P, eta: ((equivalent - rate_free) / (3.0 * G),
                                                                                  rate_free)
    return lambda law, equivalent, rate_free, G, dt, hard, eps_p, T, P, eta: bracketed_plastic_increment(
        law, equivalent, rate_free, G, dt, hard, eps_p, T, P, eta)


def law_plastic_increment_warm(law, equivalent, rate_free, G, dt, hard, eps_p, T, P, eta, x_warm, rate_warm):
    """`law_plastic_increment`'s (d, Y) and the cell's renewed warm start (x, rate, 1/us): from the law's
    `plastic_increment_warm` where it declares one, else the warm start (x_warm, rate_warm) unchanged."""
    declared = declared_law(type(law))
    if declared.plastic_increment_warm is not None:
        return declared.plastic_increment_warm(law, equivalent, rate_free, G, dt, hard, eps_p, T, P, eta, x_warm,
                                               rate_warm)
    if declared.rate_dependent and declared.plastic_increment is None:
        return bracketed_plastic_increment_warm(law, equivalent, rate_free, G, dt, hard, eps_p, T, P, eta, x_warm,
                                                rate_warm)
    d, Y = law_plastic_increment(law, equivalent, rate_free, G, dt, hard, eps_p, T, P, eta)
    return d, Y, x_warm, rate_warm


@overload(law_plastic_increment_warm, jit_options={"cache": True})
def _law_plastic_increment_warm(law, equivalent, rate_free, G, dt, hard, eps_p, T, P, eta, x_warm, rate_warm):
    declared = declared_law(law)
    kernel = declared.plastic_increment_warm
    if kernel is None and declared.rate_dependent and declared.plastic_increment is None:
        kernel = bracketed_plastic_increment_warm
    if kernel is not None:
        return lambda law, equivalent, rate_free, G, dt, hard, eps_p, T, P, eta, x_warm, rate_warm: kernel(
            law, equivalent, rate_free, G, dt, hard, eps_p, T, P, eta, x_warm, rate_warm)

    def cold(law, equivalent, rate_free, G, dt, hard, eps_p, T, P, eta, x_warm, rate_warm):
        d, Y = law_plastic_increment(law, equivalent, rate_free, G, dt, hard, eps_p, T, P, eta)
        return d, Y, x_warm, rate_warm
    return cold
