"""1D Lagrangian hydrocode for symmetric plate impact (uniaxial strain, elastic-plastic).

`run_shot(params, geometry, material, settings)` simulates one shot for one set of inputs and
returns the target's free-surface velocity history with diagnostics; the inputs are in user units
(`ShotParameters`, `Geometry`, `MaterialProperties` with `AL5083`, `HydroSettings`).
`shockcal.simulate` runs a whole design from a study config. See docs/hydro.md.
"""

from shockcal.design import ShotParameters
from shockcal.hydro.settings import AL5083, Geometry, HydroSettings, MaterialProperties
from shockcal.hydro.shot import RunResult, run_shot

__all__ = ["AL5083", "Geometry", "HydroSettings", "MaterialProperties", "RunResult", "ShotParameters", "run_shot"]
