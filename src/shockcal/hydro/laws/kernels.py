"""One call for every law inside numba kernels, chosen by the type of the law's named tuple when numba
compiles (no run-time branch, no function objects passed around, so callers stay cacheable):

    law_flow_stress(law, eps_p, strain_rate, T, P, eta) -> Mbar
    law_shear_modulus(law, G, P, T, eta) -> Mbar   (the law's G(P, T, eta), or the constant G for laws
                                                      without one: Johnson-Cook, Zerilli-Armstrong)
    law_flow_stress_at(law, G, eps_p, strain_rate, T, P, eta) -> Mbar   (with the cell's G from
                                                      law_shear_modulus, which the law does not recompute)
    law_flow_stress_cached(law, hard, G, eps_p, strain_rate, T, P, eta) -> Mbar   (law_flow_stress_at, from the
                                                      cell's cached hardening `hard` where the law can use it)
    law_hardening(law, eps_p) -> the law's cached hardening (0 for laws without one)
    law_hardening_after(law, hard, eps_p, d_eps) -> law_hardening(law, eps_p + d_eps), from the cached `hard`
                                                      where the law can (Johnson-Cook: a series, no pow)
    law_rate_free_flow_stress(law, hard, G, eps_p, T, P, eta, power_T, power)
        -> (law_flow_stress_cached at zero strain rate, power_T, power): the cell's remembered thermal power
           (Johnson-Cook: T*^m at power_T, K) read and renewed by a law that keeps one, else passed through
    law_flow_stress_floor(law, hard, G, T, eta, flow_floor, floor_hotter, floor_T) -> Mbar
        (a proven lower bound of the flow stress at any strain rate from the cell's cached hardening and
         remembered floor, -1 where the law has none)
    law_remember_floor(law, G, eps_p, T, eta, flow_floor, floor_hotter, floor_T)
        -> the cell's new remembered floor (flow_floor, floor_hotter, floor_T), the old one for laws
           that remember none

The solver skips the full flow stress of a cell whose elastic trial lies inside the floor
(`shockcal.hydro.plastic_return.plastic_return`); `hard` is recomputed only when the plastic strain changes,
the remembered floor only when a full evaluation finds the cell elastic.

Arguments and units as in `shockcal.hydro.laws` (strain rate the equivalent one, 1/us; T in K; P in
Mbar; eta = rho / rho0). The pure-Python bodies below serve outside numba (tests, notebooks).
"""

from __future__ import annotations

from numba.extending import overload

from shockcal.hydro.laws.declarations import LAWS


def declared_law(law_type):
    """The declared law whose named tuple has this numba type (or Python class)."""
    cls = getattr(law_type, "instance_class", law_type)
    for law in LAWS.values():
        if law.code_type is cls:
            return law
    raise TypeError(f"not a strength law's parameters: {law_type}")


def law_flow_stress(law, eps_p, strain_rate, T, P, eta):
    """Flow stress (Mbar) of the law whose parameters `law` holds."""
    return declared_law(type(law)).flow_stress(law, eps_p, strain_rate, T, P, eta)


def law_shear_modulus(law, G, P, T, eta):
    """The law's shear modulus (Mbar) at P (Mbar), T (K), eta; `G` (Mbar) for laws without a modulus law."""
    modulus = declared_law(type(law)).shear_modulus
    return G if modulus is None else modulus(law, P, T, eta)


@overload(law_flow_stress, jit_options={"cache": True})
def _law_flow_stress(law, eps_p, strain_rate, T, P, eta):
    kernel = declared_law(law).flow_stress
    return lambda law, eps_p, strain_rate, T, P, eta: kernel(law, eps_p, strain_rate, T, P, eta)


@overload(law_shear_modulus, jit_options={"cache": True})
def _law_shear_modulus(law, G, P, T, eta):
    modulus = declared_law(law).shear_modulus
    if modulus is None:
        return lambda law, G, P, T, eta: G
    return lambda law, G, P, T, eta: modulus(law, P, T, eta)


def law_flow_stress_at(law, G, eps_p, strain_rate, T, P, eta):
    """Flow stress (Mbar) where the law's shear modulus is G (Mbar); laws without a modulus law ignore G."""
    kernel = declared_law(type(law)).flow_stress_at
    if kernel is None:
        return law_flow_stress(law, eps_p, strain_rate, T, P, eta)
    return kernel(law, G, eps_p, strain_rate, T, P, eta)


def law_flow_stress_cached(law, hard, G, eps_p, strain_rate, T, P, eta):
    """`law_flow_stress_at`, read from the cell's cached hardening `hard` (`law_hardening(law, eps_p)`) by a law
    that declares `flow_stress_from_hardening` (the same value bit for bit)."""
    kernel = declared_law(type(law)).flow_stress_from_hardening
    if kernel is None:
        return law_flow_stress_at(law, G, eps_p, strain_rate, T, P, eta)
    return kernel(law, hard, strain_rate, T)


@overload(law_flow_stress_cached, jit_options={"cache": True})
def _law_flow_stress_cached(law, hard, G, eps_p, strain_rate, T, P, eta):
    kernel = declared_law(law).flow_stress_from_hardening
    if kernel is None:
        return lambda law, hard, G, eps_p, strain_rate, T, P, eta: law_flow_stress_at(law, G, eps_p, strain_rate, T,
                                                                                     P, eta)
    return lambda law, hard, G, eps_p, strain_rate, T, P, eta: kernel(law, hard, strain_rate, T)


def law_hardening(law, eps_p):
    """The law's hardening at `eps_p` that its floor reads (0.0 for a law without one)."""
    kernel = declared_law(type(law)).hardening
    return 0.0 if kernel is None else kernel(law, eps_p)


def law_flow_stress_floor(law, hard, G, T, eta, flow_floor, floor_hotter, floor_T):
    """A lower bound (Mbar) of the law's flow stress at any strain rate, at the cell's plastic strain (through
    `hard`), shear modulus G (Mbar), temperature (K) and eta, from the cached hardening and the remembered
    floor (flow_floor, floor_hotter, floor_T: their meaning is the law's); -1.0 when none."""
    kernel = declared_law(type(law)).flow_stress_floor
    return -1.0 if kernel is None else kernel(law, hard, G, T, eta, flow_floor, floor_hotter, floor_T)


def law_remember_floor(law, G, eps_p, T, eta, flow_floor, floor_hotter, floor_T):
    """The cell's remembered floor after a full evaluation found it elastic at this state; the given one
    for a law that remembers none."""
    kernel = declared_law(type(law)).remember_floor
    if kernel is None:
        return flow_floor, floor_hotter, floor_T
    return kernel(law, G, eps_p, T, eta, flow_floor, floor_hotter, floor_T)


@overload(law_flow_stress_at, jit_options={"cache": True})
def _law_flow_stress_at(law, G, eps_p, strain_rate, T, P, eta):
    kernel = declared_law(law).flow_stress_at
    if kernel is None:
        flow = declared_law(law).flow_stress
        return lambda law, G, eps_p, strain_rate, T, P, eta: flow(law, eps_p, strain_rate, T, P, eta)
    return lambda law, G, eps_p, strain_rate, T, P, eta: kernel(law, G, eps_p, strain_rate, T, P, eta)


@overload(law_hardening, jit_options={"cache": True})
def _law_hardening(law, eps_p):
    kernel = declared_law(law).hardening
    if kernel is None:
        return lambda law, eps_p: 0.0
    return lambda law, eps_p: kernel(law, eps_p)


@overload(law_flow_stress_floor, jit_options={"cache": True})
def _law_flow_stress_floor(law, hard, G, T, eta, flow_floor, floor_hotter, floor_T):
    kernel = declared_law(law).flow_stress_floor
    if kernel is None:
        return lambda law, hard, G, T, eta, flow_floor, floor_hotter, floor_T: -1.0
    return lambda law, hard, G, T, eta, flow_floor, floor_hotter, floor_T: kernel(law, hard, G, T, eta, flow_floor,
                                                                                  floor_hotter, floor_T)


@overload(law_remember_floor, jit_options={"cache": True})
def _law_remember_floor(law, G, eps_p, T, eta, flow_floor, floor_hotter, floor_T):
    kernel = declared_law(law).remember_floor
    if kernel is None:
        return lambda law, G, eps_p, T, eta, flow_floor, floor_hotter, floor_T: (flow_floor, floor_hotter, floor_T)
    return lambda law, G, eps_p, T, eta, flow_floor, floor_hotter, floor_T: kernel(law, G, eps_p, T, eta, flow_floor,
                                                                                   floor_hotter, floor_T)


def law_hardening_after(law, hard, eps_p, d_eps):
    """`law_hardening(law, eps_p + d_eps)` after a plastic increment d_eps from the cell's `hard` at eps_p, by a
    law that declares `hardening_after` (the same value to rounding), else evaluated afresh."""
    kernel = declared_law(type(law)).hardening_after
    return law_hardening(law, eps_p + d_eps) if kernel is None else kernel(law, hard, eps_p, d_eps)


def law_rate_free_flow_stress(law, hard, G, eps_p, T, P, eta, power_T, power):
    """The flow stress (Mbar) at zero plastic rate (`law_flow_stress_cached`), and the cell's remembered thermal
    power (power_T K, power) renewed by a law that declares `rate_free_flow_stress` (the same value to
    rounding), else passed through."""
    kernel = declared_law(type(law)).rate_free_flow_stress
    if kernel is None:
        return law_flow_stress_cached(law, hard, G, eps_p, 0.0, T, P, eta), power_T, power
    return kernel(law, hard, T, power_T, power)


@overload(law_hardening_after, jit_options={"cache": True})
def _law_hardening_after(law, hard, eps_p, d_eps):
    kernel = declared_law(law).hardening_after
    if kernel is None:
        return lambda law, hard, eps_p, d_eps: law_hardening(law, eps_p + d_eps)
    return lambda law, hard, eps_p, d_eps: kernel(law, hard, eps_p, d_eps)


@overload(law_rate_free_flow_stress, jit_options={"cache": True})
def _law_rate_free_flow_stress(law, hard, G, eps_p, T, P, eta, power_T, power):
    kernel = declared_law(law).rate_free_flow_stress
    if kernel is None:
        return lambda law, hard, G, eps_p, T, P, eta, power_T, power: (
            law_flow_stress_cached(law, hard, G, eps_p, 0.0, T, P, eta), power_T, power)
    return lambda law, hard, G, eps_p, T, P, eta, power_T, power: kernel(law, hard, T, power_T, power)
