"""Emulator speed and accuracy: fit + cross-validation, and prediction of mean and covariance.

Prints, with the load average next to every timing (the machine is shared): on the paper's FLAG
features (runs 0-499, real data), fit + K-fold + outer-check wall time and the RMSE and 90% coverage
of each scheme; fit + K-fold on 1000 runs (the paper's design with a smooth synthetic 12-feature
response, since FLAG features exist only for 500 runs); the time to predict mean and covariance of
all 12 features at 1000 inputs on one and two threads; the same on our own runs when
`results/training/features` holds them (the paper's study, `make paper`).
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pandas as pd

from shockcal.emulator.study_emulator import fit_emulator, rmse_table
from shockcal.reference import reference_dir
from shockcal.study.adapters import emulator_spec
from shockcal.study.validate import load_config
from shockcal.velocimetry.columns import CALIBRATION_FEATURES

REPO = Path(__file__).resolve().parents[1]
SHOTS = ["104S", "105S", "106S"]


def load() -> str:
    return "load " + " ".join(Path("/proc/loadavg").read_text().split()[:3])


def synthetic_features(design: pd.DataFrame, config: dict) -> dict[str, pd.DataFrame]:
    """Smooth stand-in features on the full design (velocities in m/s, plausible magnitudes)."""
    out = {}
    for shot in SHOTS:
        v = design[config["shots"][shot]["velocity_input"]] * 1e4
        a, b, n = design["A"] / 0.01, design["B"] / 0.01, design["n"] / 1.5
        y = np.column_stack([40 + 60 * a + 10 * b * n, 0.97 * v - 5 * a, 50 + 60 * a + 15 * np.sin(3 * b),
                             0.9 * v - 10 * b * (1 - n)])
        out[shot] = pd.DataFrame(y, columns=CALIBRATION_FEATURES).assign(run=design["run"])
    return out


def timed(label, fn):
    start = time.perf_counter()
    result = fn()
    print(f"  {label}: {time.perf_counter() - start:6.1f} s ({load()})")
    return result


def main() -> None:
    config = load_config(REPO / "config" / "config.yaml")
    settings = config["emulator"]
    print(f"emulator settings: {settings}")
    ref = reference_dir()
    if ref is None:
        print("reference data not found: skipping the FLAG part")
        return
    design = pd.read_csv(ref / "design.csv")
    inputs = {k: design[k].to_numpy() for k in design.columns if k != "run"}
    flag = {s: pd.read_csv(ref / f"flag_features_{s}.csv") for s in SHOTS}
    print("FLAG features, runs 0-499 (joint):")
    emulator = timed("fit", lambda: fit_emulator(design, flag, emulator_spec(config, SHOTS)))
    print(f"  ({len(emulator.blocks[0].model.gps)} components)")
    cv = [timed("closed-form LOO", lambda: emulator.cv_table("loo_closed_form"))]
    cv.append(timed(f"{settings['cv_folds']}-fold", lambda: emulator.cv_table("kfold", folds=settings["cv_folds"])))
    cv.append(timed("outer check", lambda: emulator.cv_table("outer", margin=settings["outer_margin"])))
    table = rmse_table(pd.concat(cv, ignore_index=True))
    print(table[table["shot"] == "all"].to_string(index=False))
    time_prediction(emulator, inputs)
    print("1000 runs x 12 features (synthetic response):")
    fit_and_kfold(config, design, synthetic_features(design, config), inputs)
    own = REPO / "results" / "training" / "features"
    if all((own / f"{s}.parquet").is_file() for s in SHOTS):
        print(f"our own runs ({own}):")
        fit_and_kfold(config, pd.read_parquet(REPO / "results" / "training" / "design.parquet"),
                      {s: pd.read_parquet(own / f"{s}.parquet") for s in SHOTS}, inputs)


def fit_and_kfold(config, design, features, inputs) -> None:
    """Fit (with its K-fold sd calibration) and the K-fold table, timed; then prediction."""
    start = time.perf_counter()
    emulator = timed("fit", lambda: fit_emulator(design, features, emulator_spec(config, SHOTS)))
    print(f"  ({len(emulator.blocks[0].model.gps)} components, {len(emulator.blocks[0].runs)} runs)")
    folds = config["emulator"]["cv_folds"]
    table = rmse_table(timed(f"{folds}-fold", lambda: emulator.cv_table("kfold", folds=folds)))
    print(f"  fit + K-fold: {time.perf_counter() - start:.1f} s ({load()}); "
          f"K-fold RMSE {table['rmse_m_s'].iloc[-1]:.2f} m/s, coverage {table['coverage90'].iloc[-1]:.3f}")
    time_prediction(emulator, inputs)


def time_prediction(emulator, inputs) -> None:
    """Mean and covariance of all 12 features at the 1000 design points, on 1 and 2 threads."""
    for threads in (1, 2):
        for block in emulator.blocks:
            block.model.settings = block.model.settings.replace(n_jobs=threads)
        emulator.predict(inputs, SHOTS)
        start = time.perf_counter()
        emulator.predict(inputs, SHOTS)
        print(f"  predict mean + cov of 12 features at 1000 inputs, {threads} thread(s): "
              f"{1e3 * (time.perf_counter() - start):.0f} ms ({load()})")


if __name__ == "__main__":
    main()
