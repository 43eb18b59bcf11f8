"""One hydrocode run of one shot, in user units: `run_shot(params, geometry, material, settings)`.

    from shockcal.hydro import Geometry, ShotParameters, run_shot
    params = ShotParameters(A_MPa=335, B_MPa=425, C=0.0335, n=0.42, m=1.225, velocity_m_s=204, shear_modulus_GPa=26.9)
    result = run_shot(params, Geometry(flyer_mm=3.95, target_mm=5.965, end_us=3.0), load_material("al5083"))

`result.t_us` and `result.v_m_s` are the target's free-surface velocity history (us, m/s). Any
strength law: `run_shot(LawShotParameters("sg", {...}, velocity_m_s=204), geometry, material)`, the law's
material constants (density, molar mass, melt temperature) from `material` unless `params` gives them.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numba
import numpy as np

from shockcal.hydro.laws.johnson_cook import JohnsonCook
from shockcal.hydro.parameters import LawShotParameters, ShotParameters
from shockcal.hydro.settings import Geometry, HydroSettings, MaterialProperties
from shockcal.hydro.solver import simulate
from shockcal.hydro.state import FAILURE_REASONS, STATUS_OK, LawStrength
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

    def __repr__(self) -> str:
        peak = f"{np.max(self.v_m_s):.1f} m/s" if len(self.v_m_s) else "no trace"
        end = f"{self.t_us[-1]:.3f} us" if len(self.t_us) else "-"
        why = f" ({self.reason})" if self.reason else ""
        return (f"RunResult({self.status}{why}: {len(self.t_us)} points to {end}, peak free-surface velocity {peak}, "
                f"{self.n_steps} steps in {self.wall_time_s:.3f} s, energy error {self.energy_error:.1e})")


STUDY_NUMERICS = HydroSettings()


def run_shot(params: ShotParameters | LawShotParameters, geometry: Geometry, material: MaterialProperties,
             settings: HydroSettings = STUDY_NUMERICS) -> RunResult:
    """Simulate one symmetric shot to `geometry.end_us` (or its end after the free surface's rise).

    Args:
        params: Johnson-Cook parameters, impact velocity and shear modulus (`ShotParameters`, user units),
            or any strength law's (`LawShotParameters`).
        geometry: flyer and target thickness (mm), the simulated time (us) and the plates' initial
            temperature (K; hot plates start expanded at zero pressure, `MaterialProperties.initial_state`).
        material: EOS and thermal constants of flyer and target (`shockcal.hydro.material_library.load_material`
            gives a library entry's: `load_material("al5083")`, the paper's Table II), and the constants of
            `params`' law it leaves out (`shockcal.hydro.laws.law_values`).
        settings: mesh, output sampling, artificial viscosity and time stepping (default the study's).

    Returns:
        A `RunResult`: free-surface velocity history (us, m/s) and diagnostics (the energy error relative to
        the impact's kinetic energy, the plates' initial internal energy left out). A numerical failure is
        a result with status "failed" and a reason naming the cell and time, never an exception.
    """
    nf, nt = settings.cells(geometry.flyer_mm, "Geometry.flyer_mm"), settings.cells(geometry.target_mm, "Geometry.target_mm")
    dt_out = settings.output_dt_us()
    t_out = np.arange(int(round(geometry.end_us / dt_out)) + 1) * dt_out
    velocity, strength = kernel_strength(params, material)
    initial = material.initial_state(geometry.initial_temperature_K)
    dx = settings.cell_size_um * UM_TO_CM
    stops_after_rise = geometry.stop_after_rise_us is not None
    kernel_args = dict(nf=nf, nt=nt, dx=dx, velocity=velocity, initial=initial, strength=strength,
                       material=material.code_units(), numerics=settings.numerics(), t_out=t_out,
                       rise_threshold=geometry.rise_fraction * velocity if stops_after_rise else np.inf,
                       after_rise=geometry.stop_after_rise_us if stops_after_rise else np.inf)
    load_kernel(simulate, tuple(kernel_args.values()))
    start = time.perf_counter()
    out = simulate(**kernel_args)
    wall = time.perf_counter() - start
    reason = ""
    if out.status != STATUS_OK:
        where = f" in cell {out.fail_cell}" if out.fail_cell >= 0 else ""
        body = "" if out.fail_cell < 0 else (" (flyer)" if out.fail_cell < nf else " (target)")
        reason = f"{FAILURE_REASONS[out.status]}{where}{body} at t = {out.fail_time:.5f} us after {out.n_steps} steps"
    energy = out.energy[: out.n_out]
    reached = energy[: max(1, np.count_nonzero(energy) or 1)]
    internal0 = initial.E * initial.rho * dx * (nf + nt)      # the plates' initial internal energy (0 at T_ref)
    energy_error = float(np.max(np.abs(reached - energy[0])) / (energy[0] - internal0))
    return RunResult(t_out[: out.n_out], out.v_free_surface[: out.n_out] * CM_US_TO_M_S,
                     "ok" if out.status == STATUS_OK else "failed", reason,
                     out.max_plastic_rate, out.max_temperature, out.max_plastic_strain, energy_error,
                     int(out.n_steps), wall, energy)


def kernel_strength(params: ShotParameters | LawShotParameters, material: MaterialProperties):
    """(impact velocity in cm/us, the kernel's strength tuple `LawStrength`): Johnson-Cook's tuple with the
    material's T_ref, T_melt and reference rate for `ShotParameters`, or any law's, its material constants
    from `material` unless given, for `LawShotParameters`."""
    if isinstance(params, LawShotParameters):
        return params.velocity_m_s / CM_US_TO_M_S, LawStrength(params.law_parameters(material),
                                                               params.shear_modulus_Mbar())
    inputs = params.table_iv()
    return inputs.velocity_cm_us, LawStrength(
        JohnsonCook(inputs.A_Mbar, inputs.B_Mbar, inputs.C, inputs.n, inputs.m, material.T_ref_K, material.T_melt_K,
                    material.rate_ref_per_us()), inputs.shear_modulus_Mbar)


def load_kernel(kernel, args) -> None:
    """Compile `kernel` for `args`' types, or load it from numba's cache (0.3-0.5 s once a process;
    about 70 us after), so that a run's `wall_time_s` is the run alone and the load counts as the
    job's start-up."""
    kernel.compile(tuple(numba.typeof(arg) for arg in args))
