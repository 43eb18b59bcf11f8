"""Which runs buy the most emulator accuracy where the calibration uses it: a Latin hypercube against
later waves placed from the wave-0 joint posterior, at equal run counts (the choice of
`design.waves.criterion`, docs/sequential.md).

In process, at reduced size: wave 0 is a Latin hypercube of N0 runs per shot (the study's design
stream), its emulator is fitted and calibrated jointly on the paper's published features (the
sampler at reduced settings); each arm then adds N1 runs per shot:
- lhs: another Latin hypercube over the prior box (its own seed stream);
- thinned: the wave-0 posterior's draws thinned for space filling (greedy maximin, `wave_design`);
- widened: the same, the draws widened 1.5x about their mean first;
- max_variance: the thinning among the quarter of the draws where the emulator's variance,
  relative to the observation error, is largest.
Every arm's emulator (wave 0 + its runs, refitted) predicts held-out hydrocode runs drawn from the
reference joint posterior (tests/data/reference_posterior_joint.parquet: the 1000-run emulator on the
published features) that no fit saw. Printed per arm: the RMSE over the 12 features (m/s), the share
inside the fitted error model's central 90% band, the emulator's own 10-fold RMSE (optimistic or not
on its design), the fit time, and the share of the arm's new runs inside the wave-0 emulator's 90%
band (what a band calibration on the last wave, predicted by the emulator before it, would see);
with --posteriors, the largest move of the arm's joint 5/50/95%
points from the reference's, in fractions of the box.

    nice -n 10 python benchmarks/sequential_design.py [--n0 50] [--n1 50] [--heldout 30] [--workers 2]
"""

from __future__ import annotations

import argparse
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np
import pandas as pd

from shockcal.design.posterior_draws import draw_posterior_design
from shockcal.design.waves import relative_variance, wave_design
from shockcal.emulator import fit_emulator, score_heldout
from shockcal.inference.calibration import calibrate
from shockcal.inference.summaries import SUMMARY_QUANTILES, weighted_quantiles
from shockcal.seeds import stream_seed
from shockcal.study.adapters import (
    calibration_settings,
    emulator_spec,
    extractor_settings,
    hydro_inputs,
    observed_table,
    shot_mapping,
    study_design,
)
from shockcal.study.config import prior_bounds, shot_config
from shockcal.study.validate import load_config
from shockcal.velocimetry.columns import CALIBRATION_FEATURES

REPO = Path(__file__).resolve().parents[1]
REFERENCE = REPO / "tests" / "data" / "reference_posterior_joint.parquet"


def load() -> str:
    return "load " + " ".join(Path("/proc/loadavg").read_text().split()[:3])


def study_config() -> dict:
    config = load_config(REPO / "config" / "config.yaml")
    config["observed"]["source"] = "published"        # the reference posterior's data
    return config


def simulate_chunk(task) -> pd.DataFrame:
    """Features of one shot's design rows (a worker process: the config is re-read there)."""
    from shockcal.simulators.builtin import simulate_design
    from shockcal.velocimetry.feature_tables import features_table

    shot, design = task
    config = study_config()
    traces = simulate_design(design, shot_mapping(config, shot), *hydro_inputs(config, shot_config(config, shot)))
    return features_table(traces, extractor_settings(config, shot), f"{shot} runs")


def run_features(design: pd.DataFrame, shots, pool: ProcessPoolExecutor, chunk: int = 10) -> dict[str, pd.DataFrame]:
    """Every shot's features of every design row, in chunks over the worker processes."""
    tasks = [(shot, design.iloc[i:i + chunk]) for shot in shots for i in range(0, len(design), chunk)]
    tables = list(pool.map(simulate_chunk, tasks))
    return {shot: pd.concat([t for (s, _), t in zip(tasks, tables) if s == shot], ignore_index=True) for shot in shots}


def heldout_scores(emulator, design: pd.DataFrame, features: dict[str, pd.DataFrame]) -> tuple[float, float]:
    """(RMSE m/s, share inside the error model's central 90% band) at the held-out runs every shot ran."""
    overall = score_heldout(emulator, design, features).iloc[-1]
    return float(overall["rmse_m_s"]), float(overall["coverage"])


def save(directory: Path | None, name: str, design: pd.DataFrame, features: dict[str, pd.DataFrame]) -> None:
    """Write a run set's design and each shot's features under `directory`/`name` (nothing without one)."""
    if directory is None:
        return
    (directory / name).mkdir(parents=True, exist_ok=True)
    design.to_parquet(directory / name / "design.parquet")
    for shot, table in features.items():
        table.to_parquet(directory / name / f"{shot}.parquet")


def kfold_rmse(emulator) -> float:
    cv = emulator.cv_table("kfold")
    return float(np.sqrt(np.mean((cv["predicted"] - cv["simulated"]) ** 2)))


def posterior_move(draws: pd.DataFrame, reference: pd.DataFrame, bounds) -> str:
    """The largest |q - q_ref| over the inputs and the 5/50/95% points, in fractions of the box, and where."""
    worst, where = 0.0, ""
    for name, (low, high) in bounds.items():
        ones = np.ones(len(draws)) / len(draws)
        ref = np.ones(len(reference)) / len(reference)
        q = weighted_quantiles(draws[name].to_numpy(float), ones, SUMMARY_QUANTILES)
        q_ref = weighted_quantiles(reference[name].to_numpy(float), ref, SUMMARY_QUANTILES)
        moves = np.abs(q - q_ref) / (high - low)
        if moves.max() > worst:
            worst, where = float(moves.max()), f"{name} q{round(100 * SUMMARY_QUANTILES[int(np.argmax(moves))]):02d}"
    return f"{worst:.3f} {where}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n0", type=int, default=50, help="wave-0 runs per shot (Latin hypercube)")
    parser.add_argument("--n1", type=int, default=50, help="runs per shot each arm adds")
    parser.add_argument("--heldout", type=int, default=30, help="held-out runs per shot from the reference posterior")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--posteriors", action="store_true", help="also calibrate each arm (reduced sampler)")
    parser.add_argument("--save", type=Path, help="write every design and features table here (Parquet)")
    parser.add_argument("--arms", nargs="+", default=["lhs", "thinned", "widened", "max_variance"],
                        help="the arms to run (default: all four)")
    args = parser.parse_args()
    config = study_config()
    shots, bounds = list(config["shots"]), prior_bounds(config)
    seed = config["study"]["seed"]
    spec = emulator_spec(config, shots)
    observed = observed_table(config)
    settings = calibration_settings(config, shots).with_sampler(n_live=300, n_eff=1000, draws=4000)
    reference = pd.read_parquet(REFERENCE)
    started = time.perf_counter()
    with ProcessPoolExecutor(args.workers) as pool:
        wave0, _ = study_design(config, n_runs=args.n0)
        heldout = draw_posterior_design(reference, list(bounds), args.heldout, stream_seed(seed, "waves", "benchmark_heldout"),
                                        str(REFERENCE), bounds)
        features0, held_features = run_features(wave0, shots, pool), run_features(heldout, shots, pool)
        save(args.save, "wave0", wave0, features0)
        save(args.save, "heldout", heldout, held_features)
        print(f"wave 0 ({args.n0} runs per shot) and {args.heldout} held-out runs per shot: "
              f"{time.perf_counter() - started:.0f} s ({load()})", flush=True)
        emulator0 = fit_emulator(wave0, features0, spec)
        posterior0 = calibrate(emulator0, shots, observed, settings).draws
        obs_sd = np.concatenate([0.01 * observed.set_index("shot").loc[s, CALIBRATION_FEATURES].to_numpy(float)
                                 for s in shots])
        extra_lhs, _ = study_design(config, n_runs=args.n1, seed=stream_seed(seed, "waves", "benchmark_lhs"))
        arms = {
            "lhs": extra_lhs.assign(run=extra_lhs["run"] + args.n0),
            "thinned": wave_design(posterior0, bounds, args.n1, args.n0, stream_seed(seed, "waves", "pool", 1), wave0),
            "widened": wave_design(posterior0, bounds, args.n1, args.n0, stream_seed(seed, "waves", "pool", 1), wave0, widen=1.5),
            "max_variance": wave_design(posterior0, bounds, args.n1, args.n0, stream_seed(seed, "waves", "pool", 1), wave0,
                                        criterion="max_variance",
                                        variance=lambda pool_: relative_variance(emulator0, pool_, shots, obs_sd)),
        }
        rmse0, cover0 = heldout_scores(emulator0, heldout, held_features)
        print(f"{'arm':>13}{'runs/shot':>10}{'held-out RMSE':>14}{'in 90%':>8}{'10-fold RMSE':>13}{'fit s':>7}"
              f"{'new runs in wave-0 90%':>23}{'posterior move':>22}")
        print(f"{'wave 0':>13}{args.n0:10d}{rmse0:14.2f}{cover0:8.3f}{kfold_rmse(emulator0):13.2f}{'':>7}"
              f"{posterior_move(posterior0, reference, bounds):>22}", flush=True)
        for name, added in [(name, arms[name]) for name in args.arms]:
            features = run_features(added, shots, pool)
            save(args.save, name, added, features)
            _, new_cover = heldout_scores(emulator0, added, features)
            design = pd.concat([wave0, added], ignore_index=True)
            fit_start = time.perf_counter()
            emulator = fit_emulator(design, {s: pd.concat([features0[s], features[s]], ignore_index=True)
                                             for s in shots}, spec)
            fit_s = time.perf_counter() - fit_start
            rmse, cover = heldout_scores(emulator, heldout, held_features)
            move = ""
            if args.posteriors:
                move = posterior_move(calibrate(emulator, shots, observed, settings).draws, reference, bounds)
            print(f"{name:>13}{len(design):10d}{rmse:14.2f}{cover:8.3f}{kfold_rmse(emulator):13.2f}{fit_s:7.1f}"
                  f"{new_cover:23.3f}{move:>22}  ({load()})", flush=True)
    print(f"total {time.perf_counter() - started:.0f} s")


if __name__ == "__main__":
    main()
