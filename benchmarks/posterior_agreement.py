"""Do two studies' joint posteriors agree? Each study's emulator is calibrated jointly again with
`--replicates` independent sampler runs pooled (the quantiles' Monte Carlo SE from their spread,
`calibration.replicates`), and every input's 5/50/95% points are compared: the difference against
max(3 combined Monte Carlo SE, `--box-fraction` of the prior box), the sequential design's acceptance
(docs/sequential.md, "The sequential study at full size").

    python benchmarks/posterior_agreement.py --studies results results/sequential [--replicates 3] \
        [--work /tmp/posterior_agreement]
"""

from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import yaml

from shockcal.inference.posterior_files import read_posterior
from shockcal.inference.summaries import SUMMARY_QUANTILES
from shockcal.study.config import prior_bounds
from shockcal.study.validate import load_config

SHOCKCAL = str(Path(sys.executable).parent / "shockcal")


def recalibrate(results: Path, replicates: int, out: Path) -> Path:
    """`results`' emulator calibrated jointly on its observed features with `replicates` sampler runs
    (its own config otherwise), written to `out`/joint.parquet (reused when there)."""
    posterior = out / "joint.parquet"
    if posterior.is_file():
        return posterior
    out.mkdir(parents=True, exist_ok=True)
    config = yaml.safe_load((results / "config" / "effective.yaml").read_text())
    config["calibration"]["replicates"] = replicates
    (out / "config.yaml").write_text(yaml.safe_dump(config))
    shots = list(config["shots"])
    subprocess.run([SHOCKCAL, "calibrate", "--config", str(out / "config.yaml"), "--emulator", str(results / "emulator"),
                    "--shots", *shots, "--observed", str(results / "features" / "observed.parquet"),
                    "--out", str(posterior)], check=True)
    return posterior


def agreement(first: pd.DataFrame, second: pd.DataFrame, bounds: dict, box_fraction: float) -> pd.DataFrame:
    """Per input and quantile (native-unit summaries): both values, the difference, the combined Monte
    Carlo SE, the allowance max(3 SE, box_fraction x box width) and whether the difference is within it."""
    a, b = first.set_index("parameter"), second.set_index("parameter")
    rows = []
    for name, (low, high) in bounds.items():
        for p in SUMMARY_QUANTILES:
            q = f"q{round(100 * p):02d}"
            se = float(np.hypot(a.loc[name, f"{q}_mcse"], b.loc[name, f"{q}_mcse"]))
            allowed = max(3 * se, box_fraction * (high - low))
            diff = float(b.loc[name, q] - a.loc[name, q])
            rows.append({"input": name, "quantile": q, "first": a.loc[name, q], "second": b.loc[name, q],
                         "difference": diff, "combined_mcse": se, "allowed": allowed,
                         "difference_box": diff / (high - low), "within": abs(diff) <= allowed})
    return pd.DataFrame(rows)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--studies", type=Path, nargs=2, required=True, help="two finished studies' results directories")
    parser.add_argument("--replicates", type=int, default=3)
    parser.add_argument("--box-fraction", type=float, default=0.02)
    parser.add_argument("--work", type=Path, default=Path("/tmp/posterior_agreement"))
    args = parser.parse_args()
    bounds = prior_bounds(load_config(args.studies[0] / "config" / "effective.yaml"))
    summaries = [read_posterior(recalibrate(results, args.replicates, args.work / f"study{i}")).summary(native=True)
                 for i, results in enumerate(args.studies)]
    table = agreement(*summaries, bounds, args.box_fraction)
    print(f"first: {args.studies[0]}, second: {args.studies[1]}; {args.replicates} sampler runs each; native units")
    print(table.to_string(index=False, float_format="%.5g"))
    print(f"{int(table['within'].sum())} of {len(table)} points within max(3 combined MCSE, "
          f"{args.box_fraction} of the box); largest |difference| {table['difference_box'].abs().max():.3f} of the box")


if __name__ == "__main__":
    main()
