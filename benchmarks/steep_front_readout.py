"""The read-out on steep-front records: features of noisy copies against the noise-free record's.

Writes each shot of benchmarks/steep_front.yaml (material, strength, geometry, impact velocities) with the
study's hydrocode, adds three noises, each a fixed realization (seeded): ringing like the paper's records
(AR(2), 8 ns period, `shockcal.velocimetry.record_noise.NoiseModel`) and white noise, at a marginal sd of
a share of the record's peak velocity (1% ringing, 1% and 0.5% white), and prints, per shot, noise and
calibration feature: the noise-free record's value, the noisy record's read, its read-out sd (the
parametric bootstrap `readout_replicates`, 200 replicates) and the difference in read-out sds. Goal
(docs/features.md, "Steep fronts"): every difference within 2 read-out sds, or a feature outside the
training runs that stops the calibration (`shockcal.inference.training_range`).

    python benchmarks/steep_front_readout.py [--replicates 200] [--config benchmarks/steep_front.yaml]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import yaml

from shockcal.hydro import Geometry, ShotParameters, run_shot
from shockcal.hydro.settings import MaterialProperties
from shockcal.velocimetry.columns import CALIBRATION_FEATURES
from shockcal.velocimetry.feature_tables import readout_sd
from shockcal.velocimetry.features import (
    ExtractorSettings,
    FeatureError,
    extract,
    readout_replicates,
)
from shockcal.velocimetry.record_noise import NoiseModel

HERE = Path(__file__).resolve().parent
PERIOD_SAMPLES, DAMPING = 16, 0.97            # the records' ringing: 8 ns period on the 0.5 ns grid
RINGING_AR = (2 * DAMPING * np.cos(2 * np.pi / PERIOD_SAMPLES), -DAMPING**2)
NOISES = {"1% ringing": (0.01, RINGING_AR), "1% white": (0.01, (0.0,)), "0.5% white": (0.005, (0.0,))}


def shot_records(config: dict) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """shot -> (t_us, v_m_s): the hydrocode's free-surface velocity at the config's parameters."""
    material = MaterialProperties(**config["material"])
    geometry = Geometry(**config["geometry"])
    records = {}
    for shot, velocity in config["shots"].items():
        result = run_shot(ShotParameters(velocity_m_s=velocity, **config["strength"]), geometry, material)
        records[shot] = (result.t_us, result.v_m_s)
    return records


def readout_rows(t, v, settings: ExtractorSettings, replicates: int, seed: int) -> list[dict]:
    """One row per noise and feature: noise-free value, noisy read, read-out sd (m/s)."""
    clean = extract(t, v, settings).features
    rows = []
    for k, (name, (share, ar)) in enumerate(NOISES.items()):
        noise = NoiseModel(share * float(np.max(v)), ar, 0.0, 0)
        noisy = v + noise.simulate(len(v), np.random.default_rng(seed + k))
        try:
            read = extract(t, noisy, settings)
            copies = readout_replicates(t, noisy, settings, replicates, seed + 100 + k)
        except FeatureError as exc:
            rows.append({"noise": name, "feature": "-", "error": str(exc)})
            continue
        for feature in CALIBRATION_FEATURES:
            sd = readout_sd(copies[feature])
            rows.append({"noise": name, "feature": feature, "noise_free": clean[feature], "read": read.features[feature],
                         "readout_sd": sd, "sds_off": (read.features[feature] - clean[feature]) / sd,
                         "slope_half_window_ns": 1e3 * read.slope_half_window_us,
                         "half_window_ns": 1e3 * read.noise.half_window_us})
    return rows


def main() -> None:
    import pandas as pd

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--config", default=HERE / "steep_front.yaml")
    parser.add_argument("--replicates", type=int, default=200)
    parser.add_argument("--seed", type=int, default=61)
    args = parser.parse_args()
    config = yaml.safe_load(Path(args.config).read_text())
    settings = ExtractorSettings(window_after_arrival_us=config["window_after_arrival_us"])
    for shot, (t, v) in shot_records(config).items():
        table = pd.DataFrame(readout_rows(t, v, settings, args.replicates, args.seed))
        print(f"shot {shot}:\n{table.to_string(index=False, float_format='%.2f')}\n")


if __name__ == "__main__":
    main()
