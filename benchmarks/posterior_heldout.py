"""The study's emulator on hydrocode runs drawn from its own final joint posterior, which no fit saw
(the run set "predict": predict.n_posterior_runs draws, Figs 10-13): RMSE over the 12 calibration
features (m/s), per feature and overall, and the share inside the central 90% band of the fitted
error model (each feature's error t_dof(0, scale sd^2), a Gaussian when dof is infinite). This is where
the calibration uses the emulator; K-fold on a design crowded into the posterior is optimistic there
(docs/sequential.md). Optionally a second results directory's emulator predicts the same runs
(e.g. the paper design's 1000-run emulator on the sequential study's posterior runs).

    python benchmarks/posterior_heldout.py --results results/sequential [--other-emulator results/emulator]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import stats

from shockcal.emulator.study_emulator import Emulator
from shockcal.velocimetry.features import CALIBRATION_FEATURES


def heldout(emulator: Emulator, design: pd.DataFrame, features: dict[str, pd.DataFrame]) -> pd.DataFrame:
    """Per feature of every shot: RMSE (m/s) and the share inside the error model's central 90% band,
    at the runs every shot has features for; an `all` row over every feature."""
    shots = list(features)
    ok = {s: t[t["status"] == "ok"].set_index("run") for s, t in features.items()}
    runs = sorted(set.intersection(*(set(t.index) for t in ok.values())))
    rows = design.set_index("run").loc[runs]
    mean, cov = emulator.predict({k: rows[k].to_numpy() for k in rows.columns}, shots)
    truth = np.column_stack([ok[s].loc[runs, f].to_numpy() for s in shots for f in CALIBRATION_FEATURES])
    err = mean - truth
    z = err / np.sqrt(np.diagonal(cov, axis1=1, axis2=2))
    error = emulator.blocks[0].model.error
    inside = np.abs(z) <= np.sqrt(error.scale) * stats.t.ppf(0.95, error.dof)
    names = [f"{s}:{f}" for s in shots for f in CALIBRATION_FEATURES]
    table = pd.DataFrame({"feature": names, "rmse_m_s": np.sqrt(np.mean(err ** 2, axis=0)),
                          "coverage90": inside.mean(axis=0)})
    overall = {"feature": f"all ({len(runs)} runs)", "rmse_m_s": float(np.sqrt(np.mean(err ** 2))),
               "coverage90": float(inside.mean())}
    return pd.concat([table, pd.DataFrame([overall])], ignore_index=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--results", type=Path, required=True, help="a study's results directory")
    parser.add_argument("--other-emulator", type=Path, help="another emulator directory to score on the same runs")
    args = parser.parse_args()
    design = pd.read_parquet(args.results / "predict" / "design.parquet")
    shots = sorted(p.stem for p in (args.results / "predict" / "features").glob("*.parquet"))
    features = {s: pd.read_parquet(args.results / "predict" / "features" / f"{s}.parquet") for s in shots}
    for label, directory in [("study emulator", args.results / "emulator"), ("other emulator", args.other_emulator)]:
        if directory is None:
            continue
        print(f"{label} {directory} on {args.results / 'predict'}:")
        print(heldout(Emulator.load(directory), design, features).to_string(index=False, float_format="%.3f"))


if __name__ == "__main__":
    main()
