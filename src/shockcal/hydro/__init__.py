"""1D Lagrangian hydrocode for symmetric plate impact (uniaxial strain, elastic-plastic).

`run_shot` simulates one shot for one set of inputs and returns the target's free-surface velocity
history with diagnostics; `shockcal.simulate` runs a whole design. See docs/hydro.md.
"""

from shockcal.hydro.solver import RunResult, run_shot

__all__ = ["RunResult", "run_shot"]
