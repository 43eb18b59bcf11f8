"""The `command` simulator's cost per run against the built-in hydrocode (printed, never asserted).

The same design rows of shot 104S (the quick study's 10 um cells) through `simulate_design` (in this process) and
`simulate_design_command` with examples/external_hydro (a Python process per run: start-up, shockcal's import and
numba's cache load, then the same hydrocode). Goal: the quick study with the example code within 2x of builtin's
wall time (docs/simulators.md); this shows where the extra time goes, per run.
"""

from __future__ import annotations

import os
import tempfile
import time
from pathlib import Path

from shockcal.design.tables import latin_hypercube
from shockcal.simulators.builtin import simulate_design
from shockcal.simulators.command import simulate_design_command
from shockcal.study.adapters import command_settings, hydro_inputs, shot_mapping
from shockcal.study.config import analysis_end_us, prior_bounds
from shockcal.study.validate import load_config, validate_config

REPO = Path(__file__).resolve().parents[1]
N_RUNS = 6
SHOT = "104S"


def main() -> None:
    config = load_config(REPO / "config" / "config.yaml")
    config["hydro"]["cell_size_um"] = 10.0
    example = REPO / "examples" / "external_hydro"
    config["simulator"] = {"kind": "command", "command": {
        "templates": [str(example / "deck.txt")], "command": f"{{python}} {example / 'run_hydro.py'} deck.txt trace.csv",
        "timeout_s": 300, "output": {"kind": "trace", "file": "trace.csv", "time_column": "t_us",
                                     "velocity_column": "v_m_s"}}}
    validate_config(config)
    spec, mapping = config["shots"][SHOT], shot_mapping(config, SHOT)
    design = latin_hypercube(prior_bounds(config), N_RUNS, seed=11)
    physics = hydro_inputs(config, spec)
    simulate_design(design.iloc[:1], mapping, *physics)                  # numba's cache loaded once, as a job does
    start = time.perf_counter()
    builtin = simulate_design(design, mapping, *physics)
    builtin_s = time.perf_counter() - start
    with tempfile.TemporaryDirectory() as runs:
        start = time.perf_counter()
        command = simulate_design_command(design, mapping, *physics, command_settings(config), runs,
                                          analysis_end_us(config, spec))
        command_s = time.perf_counter() - start
    same = all((a == b).all() for a, b in zip(builtin["v_m_s"], command["v_m_s"]))
    print(f"{N_RUNS} runs of {SHOT} at 10 um (load {os.getloadavg()[0]:.1f}): builtin {builtin_s / N_RUNS:.2f} s/run "
          f"(hydrocode {builtin['wall_time_s'].mean():.2f}), command {command_s / N_RUNS:.2f} s/run, "
          f"{command_s / builtin_s:.2f}x; traces identical: {same}")


if __name__ == "__main__":
    main()
