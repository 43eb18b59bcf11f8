"""Synthetic velocity records of OFHC copper for the worked example (docs/your_material.md).

Two symmetric copper-on-copper shots, 2 mm flyer on 4 mm target, at 300 and 500 m/s, run by shockcal's own
hydrocode at known Johnson-Cook parameters (`TRUTH`), with noise added: 0.5% white noise by default, or
`--noise ringing`: 1% noise that rings like a real VISAR record's (an AR(2) process with a 10 ns period,
`shockcal.velocimetry.record_noise.NoiseModel`). The level is a share of the record's peak velocity. Each
record is written as the paper's released records are ('%' comment lines, the last naming the columns
"time (us)  Up (m/s)"), one file per shot in --out, with the truth in their header.

    python examples/copper/make_records.py --out studies/copper/records

Material: the library's OFHC copper (src/shockcal/materials/copper.yaml, `material: {name: copper}` in the
study's config: Steinberg's rho0 8.93 g/cc, c0 3.94 km/s, s 1.489, gamma0 2.02; T_melt 1356 K, cv 383 J/kg/K).
Johnson-Cook parameters: Johnson & Cook, Eng. Fract. Mech. 21, 31 (1985), OFHC copper: A 90 MPa, B 292 MPa,
n 0.31, C 0.025, m 1.09; G 46 GPa.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

MATERIAL = "copper"                           # the library's entry
TRUTH = dict(A_MPa=90.0, B_MPa=292.0, C=0.025, n=0.31, m=1.09, shear_modulus_GPa=46.0)
SHOTS = {"Cu300": 300.0, "Cu500": 500.0}      # shot name -> impact velocity (m/s)
FLYER_MM, TARGET_MM, END_US = 2.0, 4.0, 2.5
RING_PERIOD_NS, RING_DAMPING = 10.0, 0.95      # the ringing noise's AR(2) poles: radius RING_DAMPING, this period


def noise_model(kind: str, sd_m_s: float, dt_us: float):
    """The record noise: white (AR order 0) or ringing (AR(2) with a RING_PERIOD_NS oscillation)."""
    from shockcal.velocimetry.record_noise import NoiseModel

    if kind == "white":
        return NoiseModel(sd_m_s, (), dt_us, 0)
    omega = 2.0 * math.pi * dt_us * 1.0e3 / RING_PERIOD_NS
    ar = (2.0 * RING_DAMPING * math.cos(omega), -RING_DAMPING**2)
    return NoiseModel(sd_m_s, ar, RING_PERIOD_NS * 1.0e-3 / 2.0, 0)


def make_record(velocity_m_s: float, noise: str, level: float, cell_size_um: float, rng):
    """(t_us, v_m_s) of one shot: the hydrocode's free-surface velocity plus noise of sd `level` x its peak."""
    from shockcal.hydro import Geometry, HydroSettings, ShotParameters, run_shot
    from shockcal.hydro.material_library import load_material

    params = ShotParameters(velocity_m_s=velocity_m_s, **TRUTH)
    run = run_shot(params, Geometry(flyer_mm=FLYER_MM, target_mm=TARGET_MM, end_us=END_US), load_material(MATERIAL),
                   HydroSettings(cell_size_um=cell_size_um))
    if run.status != "ok":
        raise SystemExit(f"make_records: the {velocity_m_s:g} m/s run failed: {run.reason}")
    dt_us = float(np.median(np.diff(run.t_us)))
    model = noise_model(noise, level * float(np.max(run.v_m_s)), dt_us)
    return run.t_us, run.v_m_s + model.simulate(len(run.t_us), rng)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="examples/copper/records", help="folder of the records (created)")
    parser.add_argument("--noise", choices=["white", "ringing"], default="white", help="the noise's kind")
    parser.add_argument("--level", type=float, help="noise sd as a share of the peak velocity "
                                                    "(default 0.005 white, 0.01 ringing)")
    parser.add_argument("--cell-size-um", type=float, default=4.0, help="the hydrocode's cell size (um)")
    parser.add_argument("--seed", type=int, default=20261128, help="seed of the noise")
    args = parser.parse_args(argv)
    level = args.level if args.level is not None else {"white": 0.005, "ringing": 0.01}[args.noise]
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(args.seed)
    for shot, velocity in SHOTS.items():
        t, v = make_record(velocity, args.noise, level, args.cell_size_um, rng)
        header = (f"%Synthetic record of the library's {MATERIAL}, shot {shot}: {FLYER_MM:g} mm flyer on {TARGET_MM:g} mm target at "
                  f"{velocity:g} m/s\n%shockcal hydrocode, {args.cell_size_um:g} um cells, Johnson-Cook "
                  + ", ".join(f"{k} {v:g}" for k, v in TRUTH.items())
                  + f"; {args.noise} noise, sd {level:g} of the peak, seed {args.seed}\n% time (us)  Up (m/s)\n")
        path = out / f"{shot}.txt"
        path.write_text(header + "".join(f"{a:.6f}\t{b:.4f}\n" for a, b in zip(t, v, strict=True)))
        print(f"wrote {path} ({len(t)} points, peak {np.max(v):.1f} m/s)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
