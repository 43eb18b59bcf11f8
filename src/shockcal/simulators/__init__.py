"""Simulators: the run sources that turn a design into velocity traces (docs/simulators.md).

`builtin` runs a design through the built-in hydrocode (`shockcal.hydro`) for one shot, one table row
per run; `command` runs an external code per run in a folder of its own (`templates` renders its deck,
`outputs` reads and checks what it writes); `archive` looks the runs up in finished ones. A run that
fails is a row with status "failed" and its reason, never a gap. Hands on a simulations table (`t_us`,
`v_m_s` per run, or the run's ten features, with its inputs and diagnostics) to the velocimetry.
"""

from shockcal._lazy import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "simulate_design": "shockcal.simulators.builtin",
    "simulate_design_command": "shockcal.simulators.command",
    "CommandSettings": "shockcal.simulators.command",
    "OutputSpec": "shockcal.simulators.outputs",
    "archive_design": "shockcal.simulators.archive",
    "ArchiveSource": "shockcal.simulators.archive",
})
