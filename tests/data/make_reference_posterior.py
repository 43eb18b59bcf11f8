"""Write tests/data/reference_posterior_joint.parquet: 6,000 equal-weight draws of the reference
joint posterior (our 1000-run emulator with its Student-t error model, the paper's published
features).

The reference itself is nautilus with 2,000 live points run to a Kish ESS of 20,000, made and kept
by `benchmarks/bench_calibration.py --only joint --replicates 0 --reference-dir
benchmarks/out/reference_published_t` (docs/calibration.md, "Reference posterior, Student-t emulator
error, the paper's published features").
Systematic resampling to 6,000 rows adds almost no noise at that ESS and keeps the file small;
`tests/test_reference_posterior.py` checks the documented shape of the posterior on it (the tip
mass, n's two modes, m's spike over a plateau). Columns: the 11 inputs in the design table's units
(A, B Mbar; G1, Delta2, Delta3 Mbar; V1-V3 cm/us) and lambda_y.
Run: python tests/data/make_reference_posterior.py [REFERENCE.parquet]
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pandas as pd

from shockcal.inference.sampler import WeightedDraws

REPO = Path(__file__).resolve().parents[2]
SOURCE = REPO / "benchmarks/out/reference_published_t/reference_joint.parquet"
OUT = Path(__file__).with_name("reference_posterior_joint.parquet")
N_DRAWS = 6000


def main(source: Path = SOURCE) -> None:
    reference = pd.read_parquet(source)
    weights = reference.pop("weight").to_numpy()
    with np.errstate(divide="ignore"):
        draws = WeightedDraws(reference.to_numpy(), np.log(weights / weights.sum()), np.zeros(len(weights)), 0.0, 0)
    rows = draws.resample(N_DRAWS, np.random.default_rng(20261124))
    reference.iloc[rows].astype("float32").reset_index(drop=True).to_parquet(OUT)
    print(f"{source}: Kish ESS {1 / np.sum((weights / weights.sum()) ** 2):.0f} -> {N_DRAWS} draws in {OUT}")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else SOURCE)
