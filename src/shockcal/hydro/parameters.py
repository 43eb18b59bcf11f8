"""The inputs of one hydrocode run of one shot: strength law, impact velocity, shear modulus.

A physicist writes them in the units of the trade, the unit in each name:

    ShotParameters(A_MPa=170, B_MPa=425, C=0.0335, n=0.42, m=1.225, velocity_m_s=204, shear_modulus_GPa=27)

The design tables keep the paper's Table IV units (Mbar, cm/us), which are the kernel's own:
`ShotParameters.from_table_iv` takes a design row's values and hands them to the kernel unconverted
(a round trip through MPa would change the last bit of about one value in eight). `table_iv()` is
the kernel's door: the only place user units become code units.

Any strength law of `shockcal.hydro.laws` (docs/strength_laws.md), by its declared parameter names:

    LawShotParameters("steinberg-guinan", {"Y0_GPa": 0.29, "Ymax_GPa": 0.68, "beta": 125, "n": 0.1,
                      "G0_GPa": 27.6, "dGdP": 1.8, "dGdT_over_G0_per_K": -6.16e-4}, velocity_m_s=204)

Laws with a shear-modulus law (Steinberg-Guinan, PTW) take G from it, cell by cell; the others
(Johnson-Cook, Zerilli-Armstrong) need `shear_modulus_GPa`. Johnson-Cook given this way runs the
same registry entry and return as `ShotParameters` (tests/test_hydro_laws.py).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, NamedTuple

from shockcal.errors import InputError
from shockcal.hydro.laws import check_given, code_parameters, get_law
from shockcal.hydro.rules import check_fields
from shockcal.units import CM_US_TO_M_S, MBAR_TO_GPA, MBAR_TO_MPA

if TYPE_CHECKING:
    from shockcal.hydro.settings import MaterialProperties

class TableIV(NamedTuple):
    """One run's inputs in the paper's Table IV units, which are the hydrocode's (Mbar, cm/us)."""

    A_Mbar: float
    B_Mbar: float
    C: float
    n: float
    m: float
    velocity_cm_us: float
    shear_modulus_Mbar: float


@dataclass(frozen=True)
class ShotParameters:
    """The inputs of one run of one shot, in user units; checked on creation (`shockcal.hydro.rules`: an
    InputError naming the field: Johnson-Cook parameters >= 0, a positive shear modulus, an impact velocity
    in (0, MAX_IMPACT_VELOCITY_M_S]).

    Args:
        A_MPa: Johnson-Cook yield stress A (MPa).
        B_MPa: Johnson-Cook hardening modulus B (MPa).
        C: Johnson-Cook strain-rate coefficient (-).
        n: Johnson-Cook hardening exponent (-).
        m: Johnson-Cook thermal-softening exponent (-).
        velocity_m_s: impact velocity of the flyer (m/s).
        shear_modulus_GPa: shear modulus G of flyer and target (GPa).
    """

    A_MPa: float
    B_MPa: float
    C: float
    n: float
    m: float
    velocity_m_s: float
    shear_modulus_GPa: float
    _table_iv: TableIV | None = field(default=None, repr=False, compare=False)

    def __post_init__(self):
        check_fields(self, {**dict.fromkeys(("A_MPa", "B_MPa", "C", "n", "m"), "nonnegative"),
                            "velocity_m_s": "impact_velocity_m_s", "shear_modulus_GPa": "positive"})

    @classmethod
    def from_table_iv(cls, A_Mbar: float, B_Mbar: float, C: float, n: float, m: float, velocity_cm_us: float,
                      shear_modulus_Mbar: float) -> ShotParameters:
        """From the paper's Table IV units (a design row: Mbar, cm/us); the kernel gets these exact values."""
        exact = TableIV(float(A_Mbar), float(B_Mbar), float(C), float(n), float(m), float(velocity_cm_us),
                        float(shear_modulus_Mbar))
        return cls(exact.A_Mbar * MBAR_TO_MPA, exact.B_Mbar * MBAR_TO_MPA, exact.C, exact.n, exact.m,
                   exact.velocity_cm_us * CM_US_TO_M_S, exact.shear_modulus_Mbar * MBAR_TO_GPA, exact)

    def table_iv(self) -> TableIV:
        """These inputs in the kernel's units (Mbar, cm/us)."""
        if self._table_iv is not None:
            return self._table_iv
        return TableIV(self.A_MPa / MBAR_TO_MPA, self.B_MPa / MBAR_TO_MPA, float(self.C), float(self.n), float(self.m),
                       self.velocity_m_s / CM_US_TO_M_S, self.shear_modulus_GPa / MBAR_TO_GPA)


@dataclass(frozen=True)
class LawShotParameters:
    """The inputs of one run of one shot under any strength law, in user units; checked on creation
    (InputError naming the model or parameter), against the law's constraints when the run's material
    fills in its constants (`law_parameters`).

    Args:
        model: the law (`shockcal.hydro.laws.get_law`: johnson-cook, steinberg-guinan, ptw,
            zerilli-armstrong, or an alias jc, sg, za).
        values: the law's parameters by their declared names, in the units the names carry (Y0_GPa,
            C0_MPa, ...); the run's material fills the material constants left out (PTW's molar mass,
            density and melt temperature, Steinberg-Guinan's melt law: `shockcal.hydro.laws.law_values`),
            declared defaults the law's conventions (eps_i, Zerilli-Armstrong's reference rate).
        velocity_m_s: impact velocity of the flyer (m/s).
        shear_modulus_GPa: G of flyer and target (GPa) for laws without a shear-modulus law
            (Johnson-Cook, Zerilli-Armstrong); None for Steinberg-Guinan and PTW, whose G(P, T) is theirs.
    """

    model: str
    values: Mapping[str, float]
    velocity_m_s: float
    shear_modulus_GPa: float | None = None

    def __post_init__(self):
        law = get_law(self.model)
        check_given(law, self.values)
        check_fields(self, {"velocity_m_s": "impact_velocity_m_s"})
        if law.shear_modulus is not None and self.shear_modulus_GPa is not None:
            raise InputError(f"{law.name}: shear_modulus_GPa given, but the law computes G(P, T) itself "
                             f"(G0_GPa is its parameter)")
        if law.shear_modulus is None and self.shear_modulus_GPa is None:
            raise InputError(f"{law.name}: shear_modulus_GPa must be a positive number (the law has no G law); "
                             "it is not given")
        check_fields(self, {"shear_modulus_GPa": "positive"})

    def law_parameters(self, material: MaterialProperties):
        """The law's named tuple in code units (Mbar, K, 1/us, g/cc), the material constants not in `values`
        from `material`; InputError naming a material key the law needs and `material` lacks, or a broken
        constraint."""
        return code_parameters(get_law(self.model), self.values, material)

    def shear_modulus_Mbar(self) -> float:
        """The constant G in Mbar, NaN (unused) for laws with their own shear-modulus law."""
        return math.nan if self.shear_modulus_GPa is None else self.shear_modulus_GPa / MBAR_TO_GPA
