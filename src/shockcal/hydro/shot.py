"""One hydrocode run of one shot, in user units: `run_shot(params, geometry, material, settings)`.

    from shockcal.hydro import Geometry, ShotParameters, run_shot
    result = run_shot(ShotParameters(0.00335, 0.00425, 0.0335, 0.42, 1.225, 0.0204, 0.269), Geometry(3.95, 5.965, 3.0))

`result.t_us` and `result.v_m_s` are the target's free-surface velocity history (us, m/s).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numba
import numpy as np

from shockcal.design import ShotParameters
from shockcal.hydro.settings import AL5083, Geometry, HydroSettings, MaterialProperties
from shockcal.hydro.solver import FAILURE_REASONS, STATUS_OK, Strength, simulate
from shockcal.units import CM_US_TO_M_S, UM_TO_CM


@dataclass
class RunResult:
    """One hydrocode run: free-surface velocity history and diagnostics (user units)."""

    t_us: np.ndarray
    v_m_s: np.ndarray
    status: str                      # "ok" or "failed"
    reason: str = ""
    max_strain_rate_per_us: float = float("nan")
    max_temperature_K: float = float("nan")
    max_plastic_strain: float = float("nan")
    energy_error: float = float("nan")
    n_steps: int = 0
    wall_time_s: float = 0.0
    energy_history: np.ndarray = field(default=None, repr=False)


STUDY_NUMERICS = HydroSettings()


def run_shot(params: ShotParameters, geometry: Geometry, material: MaterialProperties = AL5083,
             settings: HydroSettings = STUDY_NUMERICS) -> RunResult:
    """Simulate one symmetric shot to `geometry.end_us`. `params` holds the Johnson-Cook parameters,
    the impact velocity and the shear modulus in the paper's units (Mbar, cm/us); the defaults are
    Al-5083 and the study's numerics. A numerical failure is a result with status "failed" and a
    reason naming the cell and time, never an exception."""
    nf, nt = settings.cells(geometry.flyer_mm), settings.cells(geometry.target_mm)
    dt_out = settings.output_dt_us()
    t_out = np.arange(int(round(geometry.end_us / dt_out)) + 1) * dt_out
    strength = Strength(float(params.shear_modulus_Mbar), float(params.A), float(params.B), float(params.C),
                        float(params.n), float(params.m), material.rate_ref_per_us())
    args = (nf, nt, settings.cell_size_um * UM_TO_CM, float(params.velocity_cm_us), strength,
            material.code_units(), settings.numerics(), t_out)
    load_kernel(simulate, args)
    start = time.perf_counter()
    v, energy, status, cell, t_fail, steps, max_rate, max_T, max_eps = simulate(*args)
    wall = time.perf_counter() - start
    reason = ""
    if status != STATUS_OK:
        where = f" in cell {cell}" if cell >= 0 else ""
        body = "" if cell < 0 else (" (flyer)" if cell < nf else " (target)")
        reason = f"{FAILURE_REASONS[status]}{where}{body} at t = {t_fail:.5f} us after {steps} steps"
    reached = energy[: max(1, np.count_nonzero(energy) or 1)]
    energy_error = float(np.max(np.abs(reached - energy[0])) / energy[0])
    return RunResult(t_out, v * CM_US_TO_M_S, "ok" if status == STATUS_OK else "failed", reason,
                     max_rate, max_T, max_eps, energy_error, int(steps), wall, energy)


def load_kernel(kernel, args) -> None:
    """Compile `kernel` for `args`' types, or load it from numba's cache (0.3-0.5 s once a process;
    about 70 us after), so that a run's `wall_time_s` is the run alone and the load counts as the
    job's start-up."""
    kernel.compile(tuple(numba.typeof(arg) for arg in args))
