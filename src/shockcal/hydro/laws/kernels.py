"""One call for every law inside numba kernels, chosen by the type of the law's named tuple when numba
compiles (no run-time branch, no function objects passed around, so callers stay cacheable):

    law_flow_stress(law, eps_p, strain_rate, T, P, eta) -> Mbar
    law_shear_modulus(law, G, P, T, eta) -> Mbar   (the law's G(P, T, eta), or the constant G for laws
                                                      without one: Johnson-Cook, Zerilli-Armstrong)

Arguments and units as in `shockcal.hydro.laws` (strain rate the equivalent one, 1/us; T in K; P in
Mbar; eta = rho / rho0). The pure-Python bodies below serve outside numba (tests, notebooks).
"""

from __future__ import annotations

from numba.extending import overload

from shockcal.hydro.laws.declarations import LAWS


def _law_of(law_type):
    """The declared law whose named tuple has this numba type (or Python class)."""
    cls = getattr(law_type, "instance_class", law_type)
    for law in LAWS.values():
        if law.code_type is cls:
            return law
    raise TypeError(f"not a strength law's parameters: {law_type}")


def law_flow_stress(law, eps_p, strain_rate, T, P, eta):
    """Flow stress (Mbar) of the law whose parameters `law` holds."""
    return _law_of(type(law)).flow_stress(law, eps_p, strain_rate, T, P, eta)


def law_shear_modulus(law, G, P, T, eta):
    """The law's shear modulus (Mbar) at P (Mbar), T (K), eta; `G` (Mbar) for laws without a modulus law."""
    modulus = _law_of(type(law)).shear_modulus
    return G if modulus is None else modulus(law, P, T, eta)


@overload(law_flow_stress, jit_options={"cache": True})
def _law_flow_stress(law, eps_p, strain_rate, T, P, eta):
    kernel = _law_of(law).flow_stress
    return lambda law, eps_p, strain_rate, T, P, eta: kernel(law, eps_p, strain_rate, T, P, eta)


@overload(law_shear_modulus, jit_options={"cache": True})
def _law_shear_modulus(law, G, P, T, eta):
    modulus = _law_of(law).shear_modulus
    if modulus is None:
        return lambda law, G, P, T, eta: G
    return lambda law, G, P, T, eta: modulus(law, P, T, eta)
