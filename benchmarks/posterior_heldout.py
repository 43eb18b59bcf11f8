"""The study's emulator on hydrocode runs drawn from its own final joint posterior, which no fit saw
(the run set "predict": predict.n_posterior_runs draws, Figs 10-13): RMSE over the 12 calibration
features (m/s), per feature and overall; the share inside each feature's central 90% band of the fitted
error model (t_dof(0, scale sd^2), a Gaussian when dof is infinite); and the share of runs whose feature
vector lies in the error model's 90% region (the density the likelihood uses). This is where the
calibration uses the emulator, and a K-fold on a design crowded into the posterior does not measure it
(docs/sequential.md). Optionally a second results directory's emulator predicts the same runs (e.g. the
paper design's 1000-run emulator on the sequential study's posterior runs).

    python benchmarks/posterior_heldout.py --results results/sequential [--other-emulator results/emulator] \
        [--run-set verify]      # the draws `make verify` ran (it writes the same, in the records' sds too)
"""

from __future__ import annotations

import argparse
from pathlib import Path

import pandas as pd

from shockcal.emulator import Emulator, region_coverage, score_heldout


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--results", type=Path, required=True, help="a study's results directory")
    parser.add_argument("--other-emulator", type=Path, help="another emulator directory to score on the same runs")
    parser.add_argument("--run-set", default="predict", help="the run set of posterior draws (predict, or verify)")
    args = parser.parse_args()
    runs = args.results / args.run_set
    design = pd.read_parquet(runs / "design.parquet")
    shots = sorted(p.stem for p in (runs / "features").glob("*.parquet"))
    features = {s: pd.read_parquet(runs / "features" / f"{s}.parquet") for s in shots}
    for label, directory in [("study emulator", args.results / "emulator"), ("other emulator", args.other_emulator)]:
        if directory is None:
            continue
        print(f"{label} {directory} on {runs}:")
        emulator = Emulator.load(directory)
        print(score_heldout(emulator, design, features).to_string(index=False, float_format="%.3f"))
        print("the error model's 90% region of each block's feature vector:")
        print(region_coverage(emulator, design, features).to_string(index=False, float_format="%.3f"))


if __name__ == "__main__":
    main()
