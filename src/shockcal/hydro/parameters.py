"""The inputs of one hydrocode run of one shot: Johnson-Cook strength, impact velocity, shear modulus.

A physicist writes them in the units of the trade, the unit in each name:

    ShotParameters(A_MPa=170, B_MPa=425, C=0.0335, n=0.42, m=1.225, velocity_m_s=204, shear_modulus_GPa=27)

The design tables keep the paper's Table IV units (Mbar, cm/us), which are the kernel's own:
`ShotParameters.from_table_iv` takes a design row's values and hands them to the kernel unconverted
(a round trip through MPa would change the last bit of about one value in eight). `table_iv()` is
the kernel's door: the only place user units become code units.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import NamedTuple

from shockcal.units import CM_US_TO_M_S, MBAR_TO_GPA, MBAR_TO_MPA

# The Johnson-Cook inputs every shot shares (SPEC section 3), as the design tables name them.
JOHNSON_COOK_INPUTS = ("A", "B", "C", "n", "m")


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
    """The inputs of one run of one shot, in user units.

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
