"""Learning curves of both designs: what the Latin hypercube and the sequential waves buy per hydrocode run
where the calibration uses the emulator (docs/sequential.md, "Learning curves").

Reads two finished studies:
- `--paper`: the paper design (1000 Latin-hypercube runs per shot, `make paper`). Its predictive runs
  (the run set `predict`: draws from its own joint posterior, run through the hydrocode for every
  shot, never trained on) are the held-out runs, and its joint posterior is the reference.
- `--sequential`: a study in waves (`make study`); its steps (waves 0..k refitted and
  recalibrated, results/sequential/waves/step{k}) are its points, its last step the study itself.

The Latin-hypercube points below 1000 runs per shot are the study's emulator refitted on the design's
first N rows (`shockcal emulate --first-runs N`: a random subset of the hypercube, not a hypercube of
its own) and recalibrated jointly (`shockcal calibrate`, the study's settings), both written under
`--work`. Printed per point: total training runs, the held-out RMSE over the 12 features (m/s), the
share inside the error model's central 90% band (per feature) and the share of runs inside its 90%
region of the feature vector (`region_coverage`, the density the likelihood uses), and the largest move of a 5/50/95% point from the
reference in combined Monte Carlo SE and in fractions of the box. With `--figure`, the same as a PNG.

    python benchmarks/design_learning_curve.py --paper results --sequential results/sequential \
        [--sizes 100 200 333] [--work /tmp/design_curve] [--figure docs/images/design_learning_curve.png]
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

from shockcal.emulator import Emulator, region_coverage, score_heldout
from shockcal.inference.posterior_files import read_posterior
from shockcal.inference.summaries import quantile_shifts
from shockcal.study.config import prior_bounds
from shockcal.study.validate import load_config

SHOCKCAL = str(Path(sys.executable).parent / "shockcal")


def load() -> str:
    return "load " + " ".join(Path("/proc/loadavg").read_text().split()[:3])


def run_set(results: Path, name: str) -> tuple[pd.DataFrame, dict[str, pd.DataFrame]]:
    """A run set's design and every shot's features table."""
    shots = sorted(p.stem for p in (results / name / "features").glob("*.parquet"))
    return (pd.read_parquet(results / name / "design.parquet"),
            {s: pd.read_parquet(results / name / "features" / f"{s}.parquet") for s in shots})


def refit_first_runs(paper: Path, n: int, work: Path) -> tuple[Path, Path]:
    """The paper study's emulator on its training design's first `n` rows and its joint posterior, under
    `work`/lhs-`n` (reused when there): (emulator directory, posterior samples)."""
    config, out = paper / "config" / "effective.yaml", work / f"lhs-{n}"
    design, features = paper / "training" / "design.parquet", sorted((paper / "training" / "features").glob("*.parquet"))
    emulator, posterior = out / "emulator", out / "joint.parquet"
    if not (emulator / "emulator.json").is_file():
        subprocess.run([SHOCKCAL, "emulate", "--config", str(config), "--design", str(design), "--features",
                        *[f"{p.stem}={p}" for p in features], "--first-runs", str(n), "--no-cv", "--out", str(emulator)],
                       check=True, capture_output=True)
    if not posterior.is_file():
        subprocess.run([SHOCKCAL, "calibrate", "--config", str(config), "--emulator", str(emulator), "--shots",
                        *[p.stem for p in features], "--observed", str(paper / "features" / "observed.parquet"),
                        "--out", str(posterior)], check=True, capture_output=True)
    return emulator, posterior


def sequential_points(results: Path) -> list[tuple[Path, Path, int]]:
    """Each step of a sequential study: (emulator directory, joint posterior samples, runs per shot)."""
    steps = sorted((results / "waves").glob("step*"), key=lambda p: int(p.name[4:]))
    points = []
    for step in steps:
        runs = len(pd.read_parquet(step / "design.parquet"))
        if (step / "emulator").is_dir():
            points.append((step / "emulator", step / "posterior" / "joint.parquet", runs))
        else:                                          # the last step: the study's own emulator and posterior
            points.append((results / "emulator", results / "posterior" / "joint.parquet", runs))
    return points


def posterior_distance(posterior: Path, reference: pd.DataFrame, bounds: dict) -> tuple[float, str, float]:
    """The largest move of a 5/50/95% point from `reference` (a native-unit summary): in combined Monte
    Carlo SE (and where), and in fractions of the box."""
    summary = read_posterior(posterior).summary(native=True)
    shifts = quantile_shifts(reference, summary).set_index("parameter").loc[list(bounds)]
    worst = np.unravel_index(np.argmax(shifts.to_numpy()), shifts.shape)
    both = reference.set_index("parameter").loc[list(bounds)], summary.set_index("parameter").loc[list(bounds)]
    width = np.array([high - low for low, high in bounds.values()])
    box = max(float(np.max(np.abs(both[1][q] - both[0][q]) / width)) for q in ("q05", "q50", "q95"))
    return float(shifts.to_numpy()[worst]), f"{shifts.index[worst[0]]} {shifts.columns[worst[1]]}", box


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--paper", type=Path, required=True, help="the paper design's results directory")
    parser.add_argument("--sequential", type=Path, help="a sequential study's results directory")
    parser.add_argument("--sizes", type=int, nargs="+", default=[100, 200, 333],
                        help="Latin-hypercube runs per shot below the study's (first rows of its design)")
    parser.add_argument("--work", type=Path, default=Path("/tmp/design_curve"))
    parser.add_argument("--figure", type=Path, help="write the curves as a PNG here")
    args = parser.parse_args()
    config = load_config(args.paper / "config" / "effective.yaml")
    bounds = prior_bounds(config)
    held_design, held_features = run_set(args.paper, "predict")
    reference = read_posterior(args.paper / "posterior" / "joint.parquet").summary(native=True)
    n_paper = len(pd.read_parquet(args.paper / "training" / "design.parquet"))
    points = [("Latin hypercube", *refit_first_runs(args.paper, n, args.work), n) for n in args.sizes]
    points.append(("Latin hypercube", args.paper / "emulator", args.paper / "posterior" / "joint.parquet", n_paper))
    if args.sequential is not None:
        points += [("sequential", *point) for point in sequential_points(args.sequential)]
    rows = []
    for design, emulator, posterior, n in points:
        started = time.perf_counter()
        fitted = Emulator.load(emulator)
        score = score_heldout(fitted, held_design, held_features).iloc[-1]
        region = region_coverage(fitted, held_design, held_features)["coverage"].mean()
        mcse, where, box = posterior_distance(posterior, reference, bounds)
        rows.append({"design": design, "runs_per_shot": n, "training_runs": n * len(held_features),
                     "heldout_rmse_m_s": score["rmse_m_s"], "coverage90": score["coverage"],
                     "region90": region,
                     "max_move_mcse": mcse, "where": where, "max_move_box": box})
        print(f"{design} {n}/shot: {time.perf_counter() - started:.1f} s ({load()})", flush=True)
    table = pd.DataFrame(rows)
    print(f"held out: {score['feature']} x 12 features from {args.paper / 'predict'}; "
          f"reference posterior {args.paper / 'posterior' / 'joint.parquet'}")
    print(table.to_string(index=False, float_format="%.3f"))
    if args.figure is not None:
        plot(table, args.figure)


def plot(table: pd.DataFrame, path: Path) -> None:
    """RMSE and band coverage on the held-out runs, and the posterior's distance, against training runs."""
    import matplotlib
    import matplotlib.ticker
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(12, 3.6), constrained_layout=True)
    for design, marker in (("Latin hypercube", "o"), ("sequential", "s")):
        part = table[table["design"] == design]
        axes[0].plot(part["training_runs"], part["heldout_rmse_m_s"], marker=marker, label=design)
        axes[1].plot(part["training_runs"], part["coverage90"], marker=marker, label=f"{design}, per feature")
        axes[1].plot(part["training_runs"], part["region90"], marker=marker, ls=":", label=f"{design}, the vector")
        axes[2].plot(part["training_runs"], part["max_move_box"], marker=marker, label=design)
    axes[1].axhspan(0.88, 0.92, color="0.85", label="0.88-0.92")
    axes[2].axhline(0.02, color="0.5", ls="--", label="0.02 of the box")
    labels = ("held-out RMSE (m/s)", "share in the 90% band or region", "largest 5/50/95% move from 3000 runs (box)")
    for ax, label in zip(axes, labels):
        ax.set_xscale("log")
        ax.set_xticks([300, 600, 1000, 3000], ["300", "600", "1000", "3000"])
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.set_xlabel("training hydrocode runs (all shots)")
        ax.set_ylabel(label)
        ax.legend(fontsize=8)
    fig.savefig(path, dpi=120)
    print(f"figure: {path}")


if __name__ == "__main__":
    main()
