"""Does `hydro.end_time_us: per_run` keep every feature? (docs/hydro.md, "End time").

    python benchmarks/per_run_end.py RESULTS_DIR [RESULTS_DIR ...] [--run-sets training wave1 wave2]

A run that ends early takes the same steps as the longer one up to its end (tests/test_end_time.py), so
its trace is the longer trace's prefix. This reads the traces a finished study simulated with `auto`
(each study's `training` and wave run sets, its own effective config), cuts each where `per_run` would
have ended it (the window plus AUTO_END_MARGIN_US after the first sample above PER_RUN_RISE_FRACTION x
the run's impact velocity), extracts the features of both and prints per study the runs compared, those
whose ten features differ at all, the largest difference (m/s, us), the runs whose cut trace the
extractor refuses, the largest arrival after the rise (us; > 0 would break the bound) and the share of
each trace cut. Prints, never asserts; no hydrocode is run.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import pandas as pd
import yaml

from shockcal.study.adapters import extractor_settings
from shockcal.study.config import AUTO_END_MARGIN_US, PER_RUN_RISE_FRACTION
from shockcal.velocimetry.features import FeatureError, extract


def per_run_cut(t_us: np.ndarray, v_m_s: np.ndarray, impact_velocity_m_s: float, window_us: float
                ) -> tuple[float, np.ndarray]:
    """(the rise's time in us, the samples a `per_run` run keeps: up to the window plus the margin after it)."""
    rise = float(t_us[np.argmax(v_m_s > PER_RUN_RISE_FRACTION * impact_velocity_m_s)])
    return rise, t_us <= rise + window_us + AUTO_END_MARGIN_US + 1e-12


def compare_study(results: Path, run_sets: list[str]) -> dict:
    """The comparison of one study's `auto` traces with their `per_run` cuts (module docstring)."""
    config = yaml.safe_load(next((results / "config").glob("effective-*.yaml")).read_text())
    runs = differ = refused = 0
    largest, latest_arrival, cut_share = 0.0, -np.inf, []
    for run_set in run_sets:
        for shot in config["shots"]:
            settings = extractor_settings(config, shot)
            for chunk in sorted((results / run_set / "simulations" / shot).glob("chunk-*.parquet")):
                for row in pd.read_parquet(chunk).itertuples():
                    if row.status != "ok":
                        continue
                    t, v = np.asarray(row.t_us), np.asarray(row.v_m_s)
                    rise, keep = per_run_cut(t, v, row.impact_velocity_m_s, settings.window_after_arrival_us)
                    full = extract(t, v, settings)
                    runs += 1
                    cut_share.append(1.0 - keep.mean())
                    latest_arrival = max(latest_arrival, full.arrival_us - rise)
                    try:
                        cut = extract(t[keep], v[keep], settings)
                    except FeatureError:
                        refused += 1
                        continue
                    gaps = [abs(full.features[k] - cut.features[k]) for k in full.features]
                    differ += max(gaps) > 0.0
                    largest = max(largest, max(gaps))
    return {"study": str(results), "runs": runs, "features differ": differ, "largest difference": largest,
            "refused": refused, "latest arrival after the rise (us)": latest_arrival,
            "trace cut (mean share)": float(np.mean(cut_share)) if cut_share else float("nan")}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("results", nargs="+", type=Path, help="finished studies' results directories")
    parser.add_argument("--run-sets", nargs="+", default=["training", "wave1", "wave2"])
    args = parser.parse_args()
    for results in args.results:
        print(compare_study(results, args.run_sets))


if __name__ == "__main__":
    main()
