"""Where in the box the emulator's 90% bands hold: the constant sd model against the smooth one.

On the paper's FLAG features (runs 0-499, joint, the study's code path and seeds), or with `--study
DIR` on a study's own training runs (DIR/training/design.parquet and features), for each
`emulator.sd_model` (default both: constant, then smooth): fit (its 10-fold, everything refitted, is the
sd calibration, and with `smooth` the variance model is refitted per fold, so each fold is judged by a
calibration that never saw it) and the outer check (train on the runs with every design input in the
inner box [0.05, 0.95], predict the rest, with the full fit's calibration). Prints, never asserts:
- overall RMSE (m/s), 90%-band coverage and mean z^2 of both schemes, per feature coverage, and the
  Student-t error model refitted to the K-fold (dof, scale);
- per design input and fifth of its box: coverage of the 90% bands (share of held-out values inside) and
  mean z^2 (1 when the sds are right), K-fold and outer, with the worst fifth per input;
- the noise those cells would show if the sds were right everywhere: a permutation of the runs (which
  keeps each run's features together) gives each cell's sd and the spread of the smallest and largest
  of the 55 cells;
- wall times (fit with its K-fold; outer check; prediction of 1000 points) with the load beside them.
Usage: python benchmarks/emulator_variance.py [--sd-model constant smooth] [--study results]
"""

from __future__ import annotations

import argparse
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd

from shockcal.emulator.held_out import Z90
from shockcal.emulator.study_emulator import fit_emulator
from shockcal.io import read_table
from shockcal.reference import reference_dir
from shockcal.study.adapters import emulator_spec, load_study_design
from shockcal.study.validate import load_config

REPO = Path(__file__).resolve().parents[1]
SHOTS = ["104S", "105S", "106S"]
FIFTHS = 5
PERMUTATIONS = 200


def load() -> str:
    return "load " + " ".join(Path("/proc/loadavg").read_text().split()[:3])


def by_fifth(x: np.ndarray, z: np.ndarray, names) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Coverage of the 90% bands and mean z^2 per input (rows) and fifth of its box (columns), over the
    held-out values (runs x features) whose run's scaled input lies in that fifth."""
    fifth = np.clip((x * FIFTHS).astype(int), 0, FIFTHS - 1)
    inside = np.abs(z) <= Z90
    cover = [[inside[fifth[:, j] == k].mean() for k in range(FIFTHS)] for j in range(len(names))]
    z2 = [[(z[fifth[:, j] == k] ** 2).mean() for k in range(FIFTHS)] for j in range(len(names))]
    columns = [f"{k / FIFTHS:.1f}-{(k + 1) / FIFTHS:.1f}" for k in range(FIFTHS)]
    return pd.DataFrame(cover, names, columns), pd.DataFrame(z2, names, columns)


def null_spread(x: np.ndarray, z: np.ndarray, names, rng) -> tuple[float, np.ndarray, np.ndarray]:
    """Each cell's coverage sd, and the 5/50/95% points of the smallest and largest cell, when the
    runs' z values are shuffled over the box (the bands equally good everywhere), shifted so that the
    overall coverage is 0.90 (the bands right everywhere)."""
    shift = 0.9 - np.mean(np.abs(z) <= Z90)
    sds, lows, highs = [], [], []
    for _ in range(PERMUTATIONS):
        cover, _ = by_fifth(x, z[rng.permutation(len(z))], names)
        sds.append(cover.to_numpy().std())
        lows.append(cover.to_numpy().min() + shift)
        highs.append(cover.to_numpy().max() + shift)
    return float(np.mean(sds)), np.percentile(lows, [5, 50, 95]), np.percentile(highs, [5, 50, 95])


def report(label: str, x: np.ndarray, held, y: np.ndarray, names, rng) -> dict:
    err = held.mean - y[held.rows]
    z = err / held.sd
    print(f"\n  {label}: {len(held.rows)} runs x {y.shape[1]} features; RMSE {np.sqrt(np.mean(err**2)):.3f} m/s, "
          f"90% coverage {np.mean(np.abs(z) <= Z90):.3f}, mean z^2 {np.mean(z**2):.3f}")
    print("    coverage per feature: " + " ".join(f"{c:.3f}" for c in np.mean(np.abs(z) <= Z90, axis=0)))
    cover, z2 = by_fifth(x[held.rows], z, names)
    cell_sd, lows, highs = null_spread(x[held.rows], z, names, rng)
    table = cover.round(3).astype(str) + " | " + z2.round(2).astype(str)
    table["worst fifth"] = [f"{cover.columns[k]}: {cover.iloc[j, k]:.3f}"
                            for j, k in enumerate(np.abs(cover.to_numpy() - 0.9).argmax(axis=1))]
    print("    per fifth of each input's box, coverage | mean z^2:")
    print("    " + table.to_string().replace("\n", "\n    "))
    dev = np.abs(cover.to_numpy() - 0.9)
    print(f"    cells: coverage {cover.to_numpy().min():.3f}-{cover.to_numpy().max():.3f}; in 0.88-0.92: "
          f"{int(np.sum(dev <= 0.02))} of {dev.size}; within 2 binomial sd ({2 * cell_sd:.3f}) of 0.90: "
          f"{int(np.sum(dev <= 2 * cell_sd))}; mean ((c - 0.9) / sd)^2 {np.mean((dev / cell_sd) ** 2):.2f} (1 if right)")
    print(f"    right sds would give: cell sd {cell_sd:.4f}, smallest cell {lows[1]:.3f} (5-95% {lows[0]:.3f}-"
          f"{lows[2]:.3f}), largest {highs[1]:.3f} ({highs[0]:.3f}-{highs[2]:.3f})")
    return {"rmse": np.sqrt(np.mean(err**2)), "coverage": np.mean(np.abs(z) <= Z90), "z2": np.mean(z**2)}


def time_variance_model(model) -> None:
    """The variance model's own cost: one fit on the K-fold's 500 x 12 values (the calibration makes
    cv_folds + 1 of them) and its factors at 1000 points (added to every prediction)."""
    from shockcal.emulator.variance_model import VarianceModel

    v, held = model.variance, model.kfold
    x = model.x_train[held.rows]
    start = time.perf_counter()
    VarianceModel.fit(x, (held.mean - model.y_train[held.rows]) / held.sd, held.sd, v.groups)
    fit_s = time.perf_counter() - start
    points, sd = np.tile(x, (2, 1)), np.tile(held.sd, (2, 1))
    start = time.perf_counter()
    v.sd_factors(points, sd)
    print(f"  variance model: groups {v.groups}, slope on log raw sd {np.round(v.sd_slope, 3).tolist()}, ridge "
          f"penalties {v.alphas}; one fit {1e3 * fit_s:.0f} ms (x{model.settings.cv_folds + 1} in the calibration), "
          f"factors at {len(points)} points {1e3 * (time.perf_counter() - start):.1f} ms ({load()})")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sd-model", nargs="+", default=["constant", "smooth"], choices=["constant", "smooth"])
    parser.add_argument("--study", type=Path, help="a study's results folder: its training runs instead of FLAG's")
    args = parser.parse_args(argv)
    config = load_config(REPO / "config" / "config.yaml")
    if args.study is None:
        ref = reference_dir()
        if ref is None:
            print("reference data not found: nothing to measure")
            return 0
        design = pd.read_csv(ref / "design.csv")
        features = {s: pd.read_csv(ref / f"flag_features_{s}.csv") for s in SHOTS}
        source = "FLAG runs 0-499"
    else:
        design = load_study_design(args.study / "training" / "design.parquet", config)
        features = {s: read_table(args.study / "training" / "features" / f"{s}.parquet") for s in SHOTS}
        source = f"the training runs of {args.study}"
    inputs = {k: design[k].to_numpy() for k in design.columns if k != "run"}
    spec = emulator_spec(config, SHOTS)
    margin = config["emulator"]["outer_margin"]
    for sd_model in args.sd_model:
        print(f"\nsd_model {sd_model} ({source}, joint, {config['emulator']['cv_folds']}-fold, outer margin {margin})")
        start = time.perf_counter()
        emulator = fit_emulator(design, features, replace(spec, settings=spec.settings.replace(sd_model=sd_model)))
        print(f"  fit + {config['emulator']['cv_folds']}-fold calibration: {time.perf_counter() - start:.1f} s ({load()})")
        block = emulator.blocks[0]
        model, names = block.model, block.input_map.names
        start = time.perf_counter()
        outer = model.outer_check(margin, np.arange(len(names)))
        print(f"  outer check: {time.perf_counter() - start:.1f} s ({load()})")
        emulator.predict(inputs, SHOTS)
        start = time.perf_counter()
        emulator.predict(inputs, SHOTS)
        print(f"  predict mean + cov at 1000 inputs: {1e3 * (time.perf_counter() - start):.0f} ms ({load()})")
        print(f"  Student-t error model refitted to the K-fold: dof {model.error.dof:.2f}, scale {model.error.scale:.3f}")
        if model.variance is not None:
            time_variance_model(model)
        x = model.x_train[:, :len(names)]
        rng = np.random.default_rng(0)
        report("10-fold (calibration cross-fitted per fold)", x, model.kfold, model.y_train, names, rng)
        report("outer check", x, outer, model.y_train, names, rng)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
