"""Emulator speed and accuracy: fit + leave-one-out, and prediction of mean and covariance.

Prints, for both structures: fit + LOO wall time and LOO RMSE on the paper's FLAG features
(runs 0-499, real data), fit + LOO time on 1000 runs (the paper's design with a smooth synthetic
12-feature response, since FLAG features exist only for 500 runs), and the time to predict mean
and covariance of all 12 features at 1000 inputs.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pandas as pd

from shockcal.config import load_config
from shockcal.emulator import CALIBRATION_FEATURES, fit_emulator, rmse_table
from shockcal.reference import reference_dir

REPO = Path(__file__).resolve().parents[1]
SHOTS = ["104S", "105S", "106S"]


def synthetic_features(design: pd.DataFrame, config: dict) -> dict[str, pd.DataFrame]:
    """Smooth stand-in features on the full design (velocities in m/s, plausible magnitudes)."""
    out = {}
    for i, shot in enumerate(SHOTS):
        v = design[config["shots"][shot]["velocity_input"]] * 1e4
        a, b, n = design["A"] / 0.01, design["B"] / 0.01, design["n"] / 1.5
        y = np.column_stack([40 + 60 * a + 10 * b * n, 0.97 * v - 5 * a, 50 + 60 * a + 15 * np.sin(3 * b),
                             0.9 * v - 10 * b * (1 - n)])
        out[shot] = pd.DataFrame(y, columns=CALIBRATION_FEATURES).assign(run=design["run"])
    return out


def timed_fit(config, design, features):
    start = time.perf_counter()
    emulator = fit_emulator(config, design, features)
    cv = emulator.cv_table()
    return emulator, cv, time.perf_counter() - start


def main() -> None:
    config = load_config(REPO / "config" / "config.yaml")
    ref = reference_dir()
    if ref is None:
        print("reference data not found: skipping the FLAG part")
    design = pd.read_csv(ref / "design.csv") if ref else None
    for structure in ("joint", "per_shot"):
        config["emulator"]["structure"] = structure
        if ref:
            flag = {s: pd.read_csv(ref / f"flag_features_{s}.csv") for s in SHOTS}
            emulator, cv, seconds = timed_fit(config, design, flag)
            overall = rmse_table(cv).iloc[-1]
            print(f"{structure:9s} FLAG 500 runs: fit + LOO {seconds:6.1f} s, LOO RMSE {overall['rmse_m_s']:.2f} m/s, "
                  f"90% coverage {overall['coverage90']:.3f}")
            inputs = {k: design[k].to_numpy() for k in design.columns if k != "run"}
            start = time.perf_counter()
            emulator.predict(inputs, SHOTS)
            print(f"{structure:9s} predict mean + cov of 12 features at 1000 inputs: "
                  f"{1e3 * (time.perf_counter() - start):.0f} ms")
        if design is not None:
            _, _, seconds = timed_fit(config, design, synthetic_features(design, config))
            print(f"{structure:9s} 1000 runs x 12 features (synthetic response): fit + LOO {seconds:6.1f} s")


if __name__ == "__main__":
    main()
