"""Calibration speed and mixing on the real data: samples/s, ESS/s, min ESS, max R-hat per calibration.

Goals (issue 6): joint 175,000 retained samples and each single shot 250,000 in <= 60 s on 2 cores,
every parameter's bulk and tail ESS >= 1,000. Needs a fitted emulator (shockcal emulate) and the
paper's published features (../shared/data/al5083/observed_features.csv).

    .venv/bin/python benchmarks/bench_calibration.py [--emulator DIR] [--only joint] [--n-samples N]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
GOAL_SECONDS, GOAL_ESS = 60.0, 1000.0


def main(argv=None) -> int:
    from shockcal.calibration import calibrate
    from shockcal.config import load_config
    from shockcal.emulator import Emulator
    from shockcal.io import read_table
    from shockcal.reference import reference_dir

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--emulator", default=str(REPO / "results" / "emulator"), help="emulator directory")
    parser.add_argument("--config", default=str(REPO / "config" / "config.yaml"))
    parser.add_argument("--only", nargs="+", choices=["104S", "105S", "106S", "joint"],
                        default=["joint", "104S", "105S", "106S"])
    parser.add_argument("--n-samples", type=int, help="override the sample counts (a quick look)")
    args = parser.parse_args(argv)
    data = reference_dir()
    if data is None or not (Path(args.emulator) / "emulator.json").is_file():
        print(f"skipped: needs the reference data (../shared/data/al5083) and an emulator at {args.emulator}")
        return 0
    config = load_config(args.config)
    emulator = Emulator.load(args.emulator)
    observed = read_table(data / "observed_features.csv")
    print("name    samples  seconds  samples/s  min_ess_bulk  min_ess_tail  ess/s  max_rhat  goal")
    for name in args.only:
        shots = ["104S", "105S", "106S"] if name == "joint" else [name]
        start = time.perf_counter()
        samples, summary, _ = calibrate(emulator, shots, observed, config, n_samples=args.n_samples)
        seconds = time.perf_counter() - start
        ess = min(summary["ess_bulk"].min(), summary["ess_tail"].min())
        ok = seconds <= GOAL_SECONDS and ess >= GOAL_ESS and summary["converged"].all()
        print(f"{name:6s} {len(samples):8d} {seconds:8.1f} {len(samples) / seconds:10.0f} "
              f"{summary['ess_bulk'].min():13.0f} {summary['ess_tail'].min():13.0f} {ess / seconds:6.1f} "
              f"{summary['r_hat'].max():9.3f}  {'met' if ok else 'MISSED'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
