"""How the emulator's error on unseen runs falls with the training runs per shot (what a
smaller design would cost in accuracy, against what it saves in hydrocode time).

Fits the study's emulator (config/config.yaml settings) on the first N runs of the study's training
design for several N and predicts the synthetic-truth check runs (`results/check`: hydrocode runs at
inputs drawn from the prior, never trained on; `make check STUDY=paper` or the hydrocode check makes them).
Prints per N: the RMSE over the 12 calibration features (m/s), the mean z^2 of the predictive sd
(1 when the sd is honest) and the share inside the central 90% band of the fitted error model, and
the fit time. The first N rows of a Latin hypercube are not themselves a Latin hypercube: a design
made for N runs would do a little better.

    python benchmarks/emulator_learning_curve.py [--runs 250 500 750 1000] [--results results]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import pandas as pd

from shockcal.emulator import fit_emulator, score_heldout
from shockcal.study.adapters import emulator_spec
from shockcal.study.validate import load_config

REPO = Path(__file__).resolve().parents[1]


def load() -> str:
    return "load " + " ".join(Path("/proc/loadavg").read_text().split()[:3])


def ok_features(path: Path) -> pd.DataFrame:
    """The check runs' features, failed runs dropped (the training runs' are dropped by `fit_emulator`)."""
    table = pd.read_parquet(path)
    return table[table["status"] == "ok"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, nargs="+", default=[250, 500, 750, 1000])
    parser.add_argument("--results", type=Path, default=REPO / "results")
    args = parser.parse_args()
    config = load_config(REPO / "config" / "config.yaml")
    shots = list(config["shots"])
    needed = [args.results / run_set / "features" / f"{s}.parquet" for run_set in ("training", "check") for s in shots]
    missing = [str(p) for p in needed if not p.is_file()]
    if missing:
        raise SystemExit(f"missing {', '.join(missing)}: run `make paper` and `make check STUDY=paper` first")
    design = pd.read_parquet(args.results / "training" / "design.parquet")
    training = {s: pd.read_parquet(args.results / "training" / "features" / f"{s}.parquet") for s in shots}
    check_design = pd.read_parquet(args.results / "check" / "design.parquet")
    check = {s: ok_features(args.results / "check" / "features" / f"{s}.parquet") for s in shots}
    spec = emulator_spec(config, shots)
    print(f"unseen: {len(check_design)} check runs per shot; error model {config['emulator']['error_tails']}")
    print(f"{'runs':>6}{'RMSE m/s':>10}{'mean z^2':>10}{'in 90%':>8}{'fit s':>8}")
    for n in args.runs:
        kept = design["run"].iloc[:n]
        start = time.perf_counter()
        emulator = fit_emulator(design.iloc[:n], {s: t[t["run"].isin(kept)] for s, t in training.items()}, spec)
        fit_s = time.perf_counter() - start
        score = score_heldout(emulator, check_design, check).iloc[-1]
        print(f"{n:6d}{score['rmse_m_s']:10.2f}{score['mean_z2']:10.2f}{score['coverage']:8.3f}{fit_s:8.1f}  ({load()})")


if __name__ == "__main__":
    main()
