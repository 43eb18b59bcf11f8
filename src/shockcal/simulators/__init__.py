"""Simulators: the run sources that turn a design into velocity traces.

`builtin` runs a design through the built-in hydrocode (`shockcal.hydro`) for one shot, one table row
per run; a run that fails is a row with status "failed" and its reason, never a gap. Hands on a
simulations table (`t_us`, `v_m_s` per run, with the run's inputs and diagnostics) to the velocimetry.
"""

from shockcal._lazy import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "simulate_design": "shockcal.simulators.builtin",
})
