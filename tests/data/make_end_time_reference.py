"""Write tests/data/end_time_reference.csv: the features of a fixed set of runs simulated to 4 us.

The set: three seeded Latin-hypercube points per shot and two corners of the prior box where the
free surface moves latest (small A, B, G and impact velocity; strong thermal softening). Made with
the rate term at the step's plastic rate inside the return (regenerated 2026-11-29, issue 62), the
exact-CDF extractor and `hydro.end_time_us: 4.0`; `tests/test_end_time.py` checks that
`end_time_us: auto` reproduces these features within 0.05 m/s (and 0.5 ns).
Run: python tests/data/make_end_time_reference.py
"""
from __future__ import annotations

from pathlib import Path

import pandas as pd

from shockcal.design.tables import latin_hypercube
from shockcal.simulators.builtin import simulate_design
from shockcal.study.adapters import extractor_settings, hydro_inputs, shot_mapping
from shockcal.study.config import prior_bounds
from shockcal.study.validate import load_config
from shockcal.velocimetry.feature_tables import features_table

REPO = Path(__file__).resolve().parents[2]
OUT = Path(__file__).with_name("end_time_reference.csv")


def reference_design(config: dict) -> pd.DataFrame:
    """The fixed runs: 3 hypercube points (seed 12) and the two late-arrival corners."""
    design = latin_hypercube(prior_bounds(config), 3, seed=12)
    low = {k: v["min"] for k, v in config["inputs"].items()}
    softening = {**low, "m": config["inputs"]["m"]["min"], "C": config["inputs"]["C"]["max"],
                 "n": config["inputs"]["n"]["max"]}
    corners = pd.DataFrame([low, softening]).assign(run=[3, 4])
    return pd.concat([design, corners[design.columns]], ignore_index=True)


def features_at(config: dict, end_time_us, runs=None) -> pd.DataFrame:
    """Features of the reference runs (or of `runs` among them) simulated to `end_time_us`."""
    config = {**config, "hydro": {**config["hydro"], "end_time_us": end_time_us}}
    design = reference_design(config)
    if runs is not None:
        design = design[design["run"].isin(runs)]
    tables = []
    for shot, spec in config["shots"].items():
        traces = simulate_design(design, shot_mapping(config, shot), *hydro_inputs(config, spec))
        tables.append(features_table(traces, extractor_settings(config, shot)).assign(shot=shot))
    return pd.concat(tables, ignore_index=True)


if __name__ == "__main__":
    table = features_at(load_config(REPO / "config" / "config.yaml"), 4.0)
    table.to_csv(OUT, index=False, float_format="%.6f")
    print(f"wrote {len(table)} rows to {OUT}")
