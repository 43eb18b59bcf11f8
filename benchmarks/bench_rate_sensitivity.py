"""How far a rounding-level perturbation moves a trace, against the Johnson-Cook rate coefficient C:
printed, never asserted (docs/hydro.md, "Rounding and time step").

One 106S run (A = 840 MPa, B = 821 MPa, n = 0.46, m = 2.26, G = 30 GPa, nominal velocity) is run
twice per C and CFL number: as is, and with the impact velocity raised by one part in 1e12. The
table gives the median and largest |difference| of the free-surface velocity (m/s) inside the
analysis window (arrival to 1.1 us after it) and, as the scale of a converged solution, the same
for the run at half the CFL number. Without a rate term the perturbation stays at the rounding
level; with it, it grows to the size of the time-step error.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from shockcal.hydro import ShotParameters, run_shot
from shockcal.study.adapters import hydro_inputs
from shockcal.study.config import shot_config
from shockcal.study.validate import load_config

CONFIG = Path(__file__).resolve().parents[1] / "config" / "config.yaml"
SHOT = "106S"
VELOCITY_CM_US = 0.04838
PERTURBATION = 1e-12
RATE_COEFFICIENTS = (0.0, 0.0005, 0.005, 0.0295)
CFL_NUMBERS = (0.5, 0.25)
WINDOW_US = (1.0, 2.1)     # the 106S analysis window of these runs (arrival about 1.0 us)


def run(C: float, cfl: float, velocity: float, inputs):
    geometry, material, settings = inputs
    params = ShotParameters.from_table_iv(0.008397, 0.008210, C, 0.458981, 2.26, velocity, 0.30)
    return run_shot(params, geometry, material, settings.replace(cfl=cfl))


def main() -> None:
    config = load_config(CONFIG)
    inputs = hydro_inputs(config, shot_config(config, SHOT))
    print(f"load average at start: {os.getloadavg()[0]:.2f}")
    print(f"{'C':>8}{'CFL':>6}   |dv| from a 1e-12 velocity change: median / max (m/s)   CFL halved: median / max")
    for C in RATE_COEFFICIENTS:
        for cfl in CFL_NUMBERS:
            base = run(C, cfl, VELOCITY_CM_US, inputs)
            inside = (base.t_us > WINDOW_US[0]) & (base.t_us < WINDOW_US[1])
            moved = np.abs(run(C, cfl, VELOCITY_CM_US * (1 + PERTURBATION), inputs).v_m_s - base.v_m_s)[inside]
            halved = np.abs(run(C, cfl / 2, VELOCITY_CM_US, inputs).v_m_s - base.v_m_s)[inside]
            print(f"{C:8.4f}{cfl:6.2f}   {np.median(moved):12.2e} / {moved.max():.2e}"
                  f"{'':30}{np.median(halved):.2e} / {halved.max():.2e}")


if __name__ == "__main__":
    main()
