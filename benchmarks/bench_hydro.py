"""Hydrocode speed per shot at the paper's mesh (4 um) and end time (4 us): printed, never asserted.

Prints the JIT compile time (cold numba cache, a fresh cache directory), then per shot the seconds
per run on one core and zone-cycles per second (cells x time steps / wall time), for a Gray et al.
Johnson-Cook set (SPEC section 3, high rate T > RT) at the nominal velocity with G = 0.27 Mbar.
Timings are inflated when other jobs share the machine: the load average is printed with them.
"""

from __future__ import annotations

import os
import tempfile
import time
from pathlib import Path

os.environ.setdefault("NUMBA_CACHE_DIR", tempfile.mkdtemp(prefix="shockcal-bench-numba-"))

from shockcal.config import load_config, shot_config  # noqa: E402
from shockcal.design import ShotParameters  # noqa: E402
from shockcal.hydro import run_shot  # noqa: E402

CONFIG = Path(__file__).resolve().parents[1] / "config" / "config.yaml"
GRAY = dict(A=0.0017, B=0.00425, C=0.0335, n=0.42, m=1.225)
NOMINAL_V = {"104S": 0.0204, "105S": 0.03549, "106S": 0.04838}
REPEATS = 2


def main() -> None:
    config = load_config(CONFIG)
    print(f"load average at start: {os.getloadavg()[0]:.2f} (timings inflated when > 0)")
    start = time.perf_counter()
    tiny = dict(shot_config(config, "104S"), flyer_mm=0.05, target_mm=0.05)
    run_shot(ShotParameters(**GRAY, velocity_cm_us=0.0204, shear_modulus_Mbar=0.27), tiny,
             {**config, "hydro": {**config["hydro"], "end_time_us": 0.01}})
    print(f"JIT compile (cold cache): {time.perf_counter() - start:.1f} s")
    dx_um = config["hydro"]["cell_size_um"]
    print(f"{'shot':6}{'cells':>8}{'steps':>8}{'s/run':>9}{'zone-cycles/s':>16}")
    for shot, velocity in NOMINAL_V.items():
        spec = shot_config(config, shot)
        params = ShotParameters(**GRAY, velocity_cm_us=velocity, shear_modulus_Mbar=0.27)
        cells = round(spec["flyer_mm"] * 1e3 / dx_um) + round(spec["target_mm"] * 1e3 / dx_um)
        best = min((run_shot(params, spec, config) for _ in range(REPEATS)), key=lambda r: r.wall_time_s)
        print(f"{shot:6}{cells:8d}{best.n_steps:8d}{best.wall_time_s:9.2f}{cells * best.n_steps / best.wall_time_s:16.3g}")
    print(f"load average at end: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
