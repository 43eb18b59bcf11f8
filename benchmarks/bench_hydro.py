"""Hydrocode speed per shot at the paper's mesh (4 um), to the paper's end time (4 us) and to the study's
(`hydro.end_time_us`, `auto` by default), and the 4 us runs against the paper's Table I and SPEC section 2
diagnostics: printed, never asserted.

Prints the JIT compile time (cold numba cache, a fresh cache directory), then per shot the seconds
per run on one core and zone-cycles per second (cells x time steps / wall time), for a Gray et al.
Johnson-Cook set (SPEC section 3, high rate T > RT) at the nominal velocity with G = 0.27 Mbar.
Timings are inflated when other jobs share the machine: the load average is printed with them.
The Table I quantities are read off the free-surface trace as an experimentalist would (see
`wave_summary`), so they compare like with like.
"""

from __future__ import annotations

import math
import os
import tempfile
import time
from pathlib import Path

import numpy as np

os.environ.setdefault("NUMBA_CACHE_DIR", tempfile.mkdtemp(prefix="shockcal-bench-numba-"))

from shockcal.hydro import ShotParameters, run_shot  # noqa: E402
from shockcal.study.adapters import hydro_inputs  # noqa: E402
from shockcal.study.config import end_time_us, shot_config  # noqa: E402
from shockcal.study.validate import load_config  # noqa: E402

CONFIG = Path(__file__).resolve().parents[1] / "config" / "config.yaml"
GRAY = dict(A_Mbar=0.0017, B_Mbar=0.00425, C=0.0335, n=0.42, m=1.225)
NOMINAL_V = {"104S": 0.0204, "105S": 0.03549, "106S": 0.04838}
REPEATS = 2
TABLE_I = {  # sigma_HEL GPa, u_e km/s, U_s km/s, sigma_final GPa, u_p km/s, rho final g/cc (SPEC section 1)
    "104S": (0.6254, 0.0360, 5.452, 1.584, 0.1020, 2.7159),
    "105S": (0.5844, 0.0337, 5.510, 2.697, 0.1775, 2.7542),
    "106S": (0.6429, 0.0370, 5.718, 3.766, 0.2419, 2.7837),
}
PAPER_DIAGNOSTICS = {"104S": (0.7, 309, 0.015), "105S": (1.75, 322, 0.020), "106S": (3.4, 365, 0.028)}


def _crossing(t, v, level, after=0.0):
    """First time after `after` that v reaches `level`."""
    k = int(np.argmax((v >= level) & (t > after)))
    return t[k - 1] + (level - v[k - 1]) * (t[k] - t[k - 1]) / (v[k] - v[k - 1])


def wave_summary(result, spec, config, G):
    """Table I quantities from the free-surface trace: u_e and u_p are half the elastic and final
    plateaus, U_s = target thickness / plastic half-rise time (Lagrangian, t = 0 at impact),
    sigma_HEL = rho0 c_L u_e, and the final state by the jump conditions across the plastic wave."""
    rho0, K = config["material"]["rho0_g_cc"], config["material"]["eos"]["c1_Mbar"]
    c_long = math.sqrt((K + 4.0 * G / 3.0) / rho0) * 1e4                       # m/s
    t, v = result.t_us, result.v_m_s
    t_e = (spec["target_mm"] * 1e-3) / c_long * 1e6
    v_elastic = float(np.median(v[(t > t_e + 0.015) & (t < t_e + 0.04)]))
    t_rise = _crossing(t, v, 0.5 * (v_elastic + v.max()), after=t_e + 0.04)
    v_final = float(np.median(v[(t > t_rise + 0.2) & (t < t_rise + 0.5)]))
    t_p = _crossing(t, v, 0.5 * (v_elastic + v_final), after=t_e + 0.04)
    u_e, u_p = 0.5 * v_elastic, 0.5 * v_final
    U_s = spec["target_mm"] * 1e-3 / (t_p * 1e-6)
    sigma_hel = rho0 * 1e3 * c_long * u_e
    sigma_final = sigma_hel + rho0 * 1e3 * U_s * (u_p - u_e)
    strain = u_e / c_long + (u_p - u_e) / U_s
    return (sigma_hel * 1e-9, u_e * 1e-3, U_s * 1e-3, sigma_final * 1e-9, u_p * 1e-3, rho0 / (1.0 - strain))


def main() -> None:
    config = load_config(CONFIG)
    print(f"load average at start: {os.getloadavg()[0]:.2f} (timings inflated when > 0)")
    start = time.perf_counter()
    tiny = dict(shot_config(config, "104S"), flyer_mm=0.05, target_mm=0.05)
    run_shot(ShotParameters.from_table_iv(**GRAY, velocity_cm_us=0.0204, shear_modulus_Mbar=0.27),
             *hydro_inputs(config, tiny, end_us=0.01))
    print(f"JIT compile (cold cache): {time.perf_counter() - start:.1f} s")
    dx_um = config["hydro"]["cell_size_um"]
    print(f"{'shot':6}{'cells':>8}{'end us':>8}{'steps':>8}{'s/run':>9}{'zone-cycles/s':>16}")
    results = {}
    for shot, velocity in NOMINAL_V.items():
        spec = shot_config(config, shot)
        params = ShotParameters.from_table_iv(**GRAY, velocity_cm_us=velocity, shear_modulus_Mbar=0.27)
        cells = round(spec["flyer_mm"] * 1e3 / dx_um) + round(spec["target_mm"] * 1e3 / dx_um)
        for end_us in (4.0, end_time_us(config, spec)):                     # the paper's end time, then ours
            inputs = hydro_inputs(config, spec, end_us)
            best = min((run_shot(params, *inputs) for _ in range(REPEATS)), key=lambda r: r.wall_time_s)
            label = f"{end_us:.2f}"
            print(f"{shot:6}{cells:8d}{label:>8}{best.n_steps:8d}{best.wall_time_s:9.2f}"
                  f"{cells * best.n_steps / best.wall_time_s:16.3g}")
            results.setdefault(shot, best)
    print(f"load average at end: {os.getloadavg()[0]:.2f}")
    print("\nGray et al. (high rate, T > RT), nominal V, G = 0.27 Mbar: ours / Table I")
    names = ["sigma_HEL GPa", "u_e km/s", "U_s km/s", "sigma_final GPa", "u_p km/s", "rho_final g/cc"]
    print(f"{'shot':6}" + "".join(f"{n:>20}" for n in names))
    for shot, result in results.items():
        ours = wave_summary(result, shot_config(config, shot), config, 0.27)
        print(f"{shot:6}" + "".join(f"{o:>11.4g} /{p:>7.4g}" for o, p in zip(ours, TABLE_I[shot])))
    print("\nmax plastic strain rate 1/us, max temperature K, max plastic strain (target): ours / paper")
    for shot, result in results.items():
        ours = (result.max_strain_rate_per_us, result.max_temperature_K, result.max_plastic_strain)
        print(f"{shot:6}" + "".join(f"{o:>11.4g} /{p:>7.4g}" for o, p in zip(ours, PAPER_DIAGNOSTICS[shot])))


if __name__ == "__main__":
    main()
