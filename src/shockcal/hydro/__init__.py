"""1D Lagrangian hydrocode for symmetric plate impact (uniaxial strain, elastic-plastic).

`run_shot(params, geometry, material, settings)` simulates one shot for one set of inputs and
returns the target's free-surface velocity history with diagnostics; the inputs are in user units
(`ShotParameters`, `Geometry`, `MaterialProperties`, `HydroSettings`; a library material by name,
`load_material("copper")`, docs/materials.md). This package is the ground floor: it imports nothing of
the study (config, design, features). See docs/hydro.md.
"""

from shockcal.hydro.material_library import load_material, material_properties
from shockcal.hydro.parameters import LawShotParameters, ShotParameters, TableIV
from shockcal.hydro.settings import Geometry, HydroSettings, MaterialProperties
from shockcal.hydro.shot import RunResult, run_shot

__all__ = ["Geometry", "HydroSettings", "LawShotParameters", "MaterialProperties",
           "RunResult", "ShotParameters", "TableIV", "load_material", "material_properties", "run_shot"]
