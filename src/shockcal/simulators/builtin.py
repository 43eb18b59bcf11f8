"""Run a design through the hydrocode for one shot, one table row per run.

A run that fails numerically, or raises, is recorded with status "failed" and a reason; the batch
always continues. Columns of the simulations table (see docs/hydro.md):
run, shot, the shot's design inputs (Table IV units; another law's in its names' units), impact_velocity_m_s,
shear_modulus_GPa (NaN for a law with its own G law),
status, reason, max_strain_rate_per_us, max_temperature_K, max_plastic_strain, energy_error,
n_steps, wall_time_s, t_us (list, microseconds), v_m_s (list, free-surface velocity in m/s).
"""

from __future__ import annotations

import logging

import numpy as np
import pandas as pd

from shockcal.design.tables import ShotMapping
from shockcal.errors import InputError
from shockcal.hydro import Geometry, HydroSettings, MaterialProperties, run_shot
from shockcal.progress import progress

log = logging.getLogger("shockcal.simulators.builtin")
DIAGNOSTICS = ["max_strain_rate_per_us", "max_temperature_K", "max_plastic_strain", "energy_error",
               "n_steps", "wall_time_s"]
def simulation_columns(inputs: list[str]) -> list[str]:
    """The simulations table's columns, in order, for a shot that reads the design columns `inputs`."""
    return ["run", "shot", *inputs, "impact_velocity_m_s", "shear_modulus_GPa", "status", "reason", *DIAGNOSTICS,
            "t_us", "v_m_s"]


UNITS = {"impact_velocity_m_s": "m/s", "shear_modulus_GPa": "GPa", "max_strain_rate_per_us": "1/us",
         "max_temperature_K": "K", "max_plastic_strain": "-", "energy_error": "relative", "wall_time_s": "s",
         "t_us": "us", "v_m_s": "m/s"}


def simulate_design(design: pd.DataFrame, mapping: ShotMapping, geometry: Geometry, material: MaterialProperties,
                    settings: HydroSettings) -> pd.DataFrame:
    """Simulate every row of `design` for one shot; failures become rows with a reason.

    Args:
        design: design table (`run` and the inputs `mapping` reads, Table IV units).
        mapping: how the shot reads a design row (its velocity and shear-modulus inputs).
        geometry: flyer and target thickness (mm) and the simulated time (us).
        material: EOS and thermal constants (user units).
        settings: the hydrocode's numerics.

    From a study config: `shockcal.study.adapters.shot_mapping` and `hydro_inputs`. Runs done and
    time left go to stderr (`shockcal.progress`: a bar on a terminal, a log line every 30 s otherwise).
    """
    shot, inputs = mapping.shot, mapping.inputs()
    rows = []
    for record in progress(design.to_dict("records"), len(design), f"shot {shot}", "run", log):
        row = {"run": int(record["run"]), "shot": shot, **{k: float(record[k]) for k in inputs},
               "impact_velocity_m_s": np.nan, "shear_modulus_GPa": np.nan}
        try:
            params = mapping.parameters(record)        # InputError (here or in run_shot): a row that breaks the law
            row["impact_velocity_m_s"] = params.velocity_m_s
            row["shear_modulus_GPa"] = np.nan if params.shear_modulus_GPa is None else params.shear_modulus_GPa
            result = run_shot(params, geometry, material, settings)
        except InputError as exc:
            log.warning("run %s of shot %s: %s", row["run"], shot, exc)
            rows.append({**row, "status": "failed", "reason": f"InputError: {exc}",
                         **{k: np.nan for k in DIAGNOSTICS}, "t_us": [], "v_m_s": []})
            continue
        except Exception as exc:  # a run must never kill the batch; the reason is kept
            log.exception("run %s of shot %s raised", row["run"], shot)
            rows.append({**row, "status": "failed", "reason": f"{type(exc).__name__}: {exc}",
                         **{k: np.nan for k in DIAGNOSTICS}, "t_us": [], "v_m_s": []})
            continue
        if result.status != "ok":
            log.warning("run %s of shot %s failed: %s", row["run"], shot, result.reason)
        rows.append({**row, "status": result.status, "reason": result.reason,
                     **{k: getattr(result, k) for k in DIAGNOSTICS},
                     "t_us": result.t_us, "v_m_s": result.v_m_s})
    columns = ["run", "shot", *inputs, "impact_velocity_m_s", "shear_modulus_GPa", "status", "reason", *DIAGNOSTICS,
               "t_us", "v_m_s"]
    table = pd.DataFrame(rows, columns=columns)
    table["n_steps"] = table["n_steps"].astype("Int64")
    return table
