"""An emulator input derived from the strength law: ln of its yield stress.

PTW's yield at zero plastic strain, y0 - (y0 - yinf) erf(kappa T^ ln(gamma xi_dot / epsdot)) times 2 G,
falls from y0 to yinf across a narrow band of kappa and gamma: on one side of that band a trace has an
elastic precursor, on the other none. A GP on the law's own inputs sees that edge only where runs lie on
both sides of it, and smooths a precursor into the region without one (docs/models.md). The yield itself,
one more input, turns the edge into a coordinate: v_elastic is a smooth function of it.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field

import numpy as np

from shockcal.hydro.laws import get_law, yield_stress_MPa


@dataclass(frozen=True)
class YieldInput:
    """ln(Y / 1 MPa), Y the flow stress of strength law `model` at zero plastic strain, equivalent strain rate
    `strain_rate_per_s` (1/s) and temperature `temperature_K` (K) (`shockcal.hydro.laws.yield_stress_MPa`),
    from the design columns `columns`: the law's parameters by their declared names and units, and the law's
    material constants `constants` (by parameter name: PTW's M_g_per_mol, rho0_g_per_cc, T_melt_K, from the
    study's material, `shockcal.study.strength_config.material_constants`)."""

    model: str
    columns: tuple[str, ...]
    strain_rate_per_s: float
    temperature_K: float
    constants: dict[str, float] = field(default_factory=dict)

    name = "ln_yield_MPa"

    def values(self, inputs) -> np.ndarray:
        """The input at every row of `inputs` (a mapping or DataFrame of the design columns)."""
        columns = {c: np.asarray(inputs[c], dtype=float) for c in self.columns}
        stress = yield_stress_MPa(get_law(self.model), {**self.constants, **columns}, self.strain_rate_per_s,
                                  self.temperature_K)
        if not np.all(stress > 0):
            bad = int(np.argmin(stress > 0))
            raise ValueError(f"{self.model}: yield stress {stress[bad]:g} MPa at row {bad} is not positive; "
                             "its logarithm cannot be an emulator input")
        return np.log(stress)

    def to_json(self) -> dict:
        return {**asdict(self), "columns": list(self.columns)}

    @classmethod
    def from_json(cls, d: dict) -> YieldInput:
        return cls(str(d["model"]), tuple(d["columns"]), float(d["strain_rate_per_s"]), float(d["temperature_K"]),
                   {str(k): float(v) for k, v in d.get("constants", {}).items()})
