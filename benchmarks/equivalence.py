"""Is a speed change statistically invisible? (the criterion for speed changes, docs/hydro.md "Speed").

    python benchmarks/equivalence.py features --out ref.parquet                 # the code on PYTHONPATH
    python benchmarks/equivalence.py features --out floor.parquet --perturb 1e-12
    python benchmarks/equivalence.py compare ref.parquet candidate.parquet floor.parquet

`features` runs the first `--runs` rows (default 30) of the study's training design (the config's
Latin hypercube, `study.seed`) through the hydrocode and the extractor for every shot, with each input
optionally multiplied by (1 + perturb s), s = +-1 seeded per run and input: a perturbation of 1e-12
shows the rounding floor, the spread any change of arithmetic order gives. `compare` prints, per
shot and calibration feature, the median, 90% quantile and maximum of |candidate - reference| beside
the same of |floor - reference| (m/s), and over all of them the share of candidate differences
above the floor's 90% quantile of the same feature (a change at the rounding floor puts about 10%
there). Run each `features` call with the code version it measures on PYTHONPATH.
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np
import pandas as pd

REPO = Path(__file__).resolve().parents[1]
CONFIG = REPO / "config" / "config.yaml"


def features(out: str, runs: int, perturb: float, config_path: Path, cfl: float | None) -> None:
    from shockcal.simulators.builtin import simulate_design
    from shockcal.study.adapters import extractor_settings, hydro_inputs, shot_mapping, study_design
    from shockcal.study.validate import load_config
    from shockcal.velocimetry.feature_tables import features_table

    config = load_config(config_path)
    if cfl is not None:
        config["hydro"]["cfl"] = cfl
    design, _ = study_design(config, lhs=True)
    design = design.iloc[:runs].copy()
    names = [c for c in design.columns if c != "run"]
    signs = np.random.default_rng(1).choice([-1.0, 1.0], size=(len(design), len(names)))
    design[names] = design[names].to_numpy() * (1.0 + perturb * signs)
    tables, hydro_s = [], 0.0
    start = time.perf_counter()
    for shot in config["shots"]:
        traces = simulate_design(design, shot_mapping(config, shot), *hydro_inputs(config, config["shots"][shot]))
        hydro_s += traces["wall_time_s"].sum()
        tables.append(features_table(traces, extractor_settings(config, shot)).assign(shot=shot))
    table = pd.concat(tables, ignore_index=True)
    table.to_parquet(out)
    print(f"{len(table)} runs -> {out}: hydrocode {hydro_s:.1f} s, total {time.perf_counter() - start:.1f} s "
          f"(load {os.getloadavg()[0]:.2f})")


def compare(reference: str, candidate: str, floor: str) -> None:
    from shockcal.velocimetry.columns import CALIBRATION_FEATURES

    keys = ["shot", "run"]
    ref, cand, flo = (pd.read_parquet(p).set_index(keys).sort_index() for p in (reference, candidate, floor))
    ok = (ref["status"] == "ok") & (cand["status"] == "ok") & (flo["status"] == "ok")
    print(f"{int(ok.sum())} of {len(ok)} runs ok in all three; |difference| in m/s: median / 90% / max")
    print(f"{'shot':6}{'feature':11}{'candidate':>26}{'floor (1e-12)':>26}")
    above = []
    for shot in ref.index.get_level_values("shot").unique():
        for feature in CALIBRATION_FEATURES:
            rows = ok.loc[shot]
            d_cand = (cand.loc[shot, feature] - ref.loc[shot, feature]).abs()[rows]
            d_floor = (flo.loc[shot, feature] - ref.loc[shot, feature]).abs()[rows]
            above.append(np.mean(d_cand > np.quantile(d_floor, 0.9)))
            fmt = lambda d: f"{np.median(d):8.3g}{np.quantile(d, 0.9):9.3g}{d.max():9.3g}"  # noqa: E731
            print(f"{shot:6}{feature:11}{fmt(d_cand):>26}{fmt(d_floor):>26}")
    print(f"share of candidate differences above the floor's 90% quantile: {np.mean(above):.3f} (floor itself: 0.10)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    f = sub.add_parser("features")
    f.add_argument("--out", required=True)
    f.add_argument("--runs", type=int, default=30)
    f.add_argument("--perturb", type=float, default=0.0)
    f.add_argument("--config", type=Path, default=CONFIG, help="study config (default config/config.yaml)")
    f.add_argument("--cfl", type=float, help="override hydro.cfl")
    c = sub.add_parser("compare")
    c.add_argument("reference")
    c.add_argument("candidate")
    c.add_argument("floor")
    args = parser.parse_args()
    if args.command == "features":
        features(args.out, args.runs, args.perturb, args.config, args.cfl)
    else:
        compare(args.reference, args.candidate, args.floor)


if __name__ == "__main__":
    main()
