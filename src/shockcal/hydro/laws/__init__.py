"""Strength laws as small numba kernels behind one interface.

Each law has a named tuple of parameters in code units (Mbar, K, 1/us, g/cc) and a kernel

    flow_stress(law, eps_p, strain_rate, T, P, eta) -> Mbar

with `eps_p` the equivalent plastic strain, `strain_rate` the equivalent strain rate (1/us), `T` the
temperature (K), `P` the pressure (Mbar, positive in compression) and `eta` = rho / rho0; a law
ignores what it does not depend on. Laws whose shear modulus varies also have
`shear_modulus(law, P, T, eta) -> Mbar`. The laws: `johnson-cook` (today's hydrocode law, bit for
bit), `steinberg-guinan`, `ptw` (Preston-Tonks-Wallace) and `zerilli-armstrong` (fcc). Their
parameters, in user units with the conversion to code units, are declared in `declarations.py`;
those that are properties of the material (density, molar mass, melt temperature) come from the
study's `MaterialProperties` through `law_values`, the one place that fills them; prior boxes for
aluminium with sources in config/models.yaml (`boxes.py`). The solver calls them through
`kernels.py` (`law_flow_stress`, `law_shear_modulus`); docs/strength_laws.md.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import TYPE_CHECKING

import numpy as np

from shockcal.errors import InputError
from shockcal.hydro.laws.declarations import ALIASES, DEFAULT_COLUMNS, DEFAULT_MODEL, LAWS, Law, Param
from shockcal.units import MBAR_TO_GPA, PER_S_TO_PER_US

if TYPE_CHECKING:
    from shockcal.hydro.settings import MaterialProperties

MBAR_TO_MPA = 1.0e3 * MBAR_TO_GPA

__all__ = ["DEFAULT_COLUMNS", "DEFAULT_MODEL", "LAWS", "Law", "Param", "check_given", "code_parameters", "flow_stress_at_states",
           "flow_stress_curve", "get_law", "law_values", "melt_temperature_K", "shear_modulus_gpa", "yield_stress_MPa"]


def get_law(name: str) -> Law:
    """The law called `name` (or an alias: jc, sg, za, preston-tonks-wallace); InputError if unknown."""
    key = ALIASES.get(name.lower(), name.lower())
    if key not in LAWS:
        raise InputError(f"unknown strength model '{name}' (known: {', '.join(LAWS)})")
    return LAWS[key]


def law_values(law: Law, values: Mapping, material: MaterialProperties | Mapping | None) -> dict:
    """`values` (by parameter name) completed with the material's constants: each parameter declared with a
    `material` field (PTW's M_g_per_mol, rho0_g_per_cc, T_melt_K; Steinberg-Guinan's melt law T_m0_K, gamma0,
    a; Johnson-Cook's T_ref_K, T_melt_K, rate_ref_per_s) and not in `values` takes that `MaterialProperties`
    field's value (same unit); a value in `values` overrides it. The one place a law's material constants are
    filled, for the library (`run_shot`) and the study config alike. A constant that neither gives is an
    InputError naming the material key.

    Args:
        law: the strength law.
        values: parameter values by declared name, in the units the names carry.
        material: the flyer and target material, as `MaterialProperties` or a study config's (resolved)
            `material` section, a mapping of the same keys; None: no material (every material constant must
            be in `values`).
    """
    filled = dict(values)
    for param in law.params:
        if param.material is None or param.name in filled:
            continue
        value = material.get(param.material) if isinstance(material, Mapping) else getattr(material, param.material, None)
        if value is None:
            raise InputError(f"material.{param.material}: missing; {law.name}'s {param.name} is this property of the "
                             f"material (give material.{param.material}, or {param.name} to the law)")
        filled[param.name] = value
    return filled


def check_given(law: Law, values: Mapping) -> None:
    """Check parameter values before the material's constants are filled in (`law_values`): InputError naming
    an unknown parameter, a non-finite value, or a missing one that neither a default nor the material gives."""
    _names_known(law, values)
    bad = [k for k, v in values.items() if not _finite(v)]
    if bad:
        raise InputError(f"{law.name}: parameter {', '.join(bad)} is not a finite number")
    missing = [p.name for p in law.params if p.name not in values and p.calibrated]
    if missing:
        raise InputError(f"{law.name}: missing parameter {', '.join(missing)}")


def user_values(law: Law, values: Mapping[str, float]) -> dict[str, float]:
    """The user's values (the material's constants filled in, `law_values`) completed with the declared
    defaults; InputError naming an unknown or missing parameter, a non-finite value or a violated constraint."""
    merged = _completed(law, values)
    bad = [k for k, v in merged.items() if not _finite(v)]
    if bad:
        raise InputError(f"{law.name}: parameter {', '.join(bad)} is not a finite number")
    for text, holds in law.constraints:
        if not holds(merged):
            raise InputError(f"{law.name}: parameters violate {text}")
    return merged


def _completed(law: Law, values: Mapping):
    """`values` completed with the declared defaults, by parameter name; InputError naming an unknown
    or missing parameter."""
    _names_known(law, values)
    merged = {p.name: values.get(p.name, p.default) for p in law.params}
    missing = [k for k, v in merged.items() if v is None]
    if missing:
        raise InputError(f"{law.name}: missing parameter {', '.join(missing)}")
    return merged


def _finite(value) -> bool:
    """Whether a value (a number or an array of them) is finite throughout."""
    return math.isfinite(value) if isinstance(value, float | int) else bool(np.all(np.isfinite(value)))


def _names_known(law: Law, values: Mapping) -> None:
    known = set(law.names())
    unknown = [k for k in values if k not in known]
    if unknown:
        raise InputError(f"{law.name}: unknown parameter {', '.join(unknown)} (parameters: {', '.join(law.names())})")


def code_parameters(law: Law, values: Mapping[str, float], material: MaterialProperties | None = None):
    """The law's named tuple in code units from user values (names and units of `law.params`), the material
    constants not in `values` from `material` (`law_values`); an unknown or missing parameter of the law's own
    is named before a material key."""
    check_given(law, values)
    merged = user_values(law, law_values(law, values, material))
    return law.code_type(**{p.field: float(merged[p.name]) * p.to_code for p in law.params})


def flow_stress_curve(law: Law, values: Mapping[str, float], plastic_strains, strain_rate_per_s: float,
                      temperature_K: float, pressure_GPa: float = 0.0, density_ratio: float = 1.0,
                      material: MaterialProperties | None = None) -> np.ndarray:
    """Flow stress (MPa) at each equivalent plastic strain, at a constant equivalent strain rate (1/s),
    temperature (K), pressure (GPa) and density ratio rho/rho0; the material constants not in `values` from
    `material` (`law_values`)."""
    return flow_stress_at_states(law, values, [(e, strain_rate_per_s, temperature_K, pressure_GPa, density_ratio)
                                               for e in np.asarray(plastic_strains, dtype=float)], material)


def flow_stress_at_states(law: Law, values: Mapping[str, float], states,
                          material: MaterialProperties | None = None) -> np.ndarray:
    """Flow stress (MPa) of one parameter set (checked once) at each state (equivalent plastic strain,
    equivalent strain rate 1/s, temperature K, pressure GPa, density ratio rho/rho0); the material constants not
    in `values` from `material` (`law_values`)."""
    params = code_parameters(law, values, material)
    return np.array([law.flow_stress(params, float(eps), rate_per_s * PER_S_TO_PER_US, float(T), P_GPa / MBAR_TO_GPA,
                                     float(eta)) for eps, rate_per_s, T, P_GPa, eta in states]) * MBAR_TO_MPA


def yield_stress_MPa(law: Law, values: Mapping[str, np.ndarray], strain_rate_per_s: float,
                     temperature_K: float, material: MaterialProperties | None = None) -> np.ndarray:
    """The flow stress (MPa) at zero plastic strain of many parameter sets, at a constant equivalent strain
    rate (1/s) and temperature (K), zero pressure and the reference density.

    `values` maps the law's parameter names (user units, as `flow_stress_curve`) to arrays of one length
    (scalars broadcast); `material` fills the material constants left out (`law_values`), declared defaults
    the rest. The rows are not checked
    against the law's constraints (`user_values` checks one set): this is the emulator's input map, which
    evaluates the law at every sampler point of a box whose corners meet them."""
    merged = _completed(law, law_values(law, values, material))
    by_field = {p.field: np.asarray(merged[p.name], dtype=float) * p.to_code for p in law.params}
    columns = np.broadcast_arrays(*(by_field[field] for field in law.code_type._fields))
    rate, T = strain_rate_per_s * PER_S_TO_PER_US, float(temperature_K)
    stress = np.array([law.flow_stress(law.code_type(*row), 0.0, rate, T, 0.0, 1.0)
                       for row in zip(*(np.atleast_1d(c) for c in columns), strict=True)])
    return stress.reshape(columns[0].shape) * MBAR_TO_MPA


def shear_modulus_gpa(law: Law, values: Mapping[str, float], temperature_K: float, pressure_GPa: float = 0.0,
                      density_ratio: float = 1.0, material: MaterialProperties | None = None) -> float | None:
    """The law's shear modulus (GPa) at the state, or None for laws without a shear-modulus law; the material
    constants not in `values` from `material` (`law_values`)."""
    if law.shear_modulus is None:
        return None
    params = code_parameters(law, values, material)
    G = law.shear_modulus(params, pressure_GPa / MBAR_TO_GPA, float(temperature_K), float(density_ratio))
    return G * MBAR_TO_GPA


def melt_temperature_K(law: Law, values: Mapping[str, float], density_ratio: float = 1.0,
                       material: MaterialProperties | None = None) -> float | None:
    """The law's melting temperature (K) at the density ratio rho/rho0, at and above which its flow stress
    is zero, or None for a law without a melt cut-off (Zerilli-Armstrong); the material constants not in
    `values` from `material` (`law_values`)."""
    if law.melt_temperature is None:
        return None
    return float(law.melt_temperature(code_parameters(law, values, material), float(density_ratio)))
