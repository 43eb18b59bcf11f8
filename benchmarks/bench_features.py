"""Feature extraction speed: milliseconds per trace, printed, never asserted (goal: 50 ms/trace).

Times `features_table` (the `shockcal features` code path) on 30 simulated-like traces (two-step
Gaussian-CDF traces with varied arrival, plateaus and rise widths on the 0.5 ns grid of a 4 us run,
8001 points) and `extract_features` on the three measured records shipped in data/al5083,
after a warm-up. Both are timed with the default thread pools and with one thread each: scikit-learn's
k-means initialization uses OpenMP, which costs more than it saves on 1-D data on a busy machine.
Timings are inflated when other jobs share the machine: the load average is printed with them.
"""

from __future__ import annotations

import os
import time
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.stats import norm
from threadpoolctl import threadpool_limits

from shockcal.features import extract_features, features_table
from shockcal.records import read_record
from shockcal.study.adapters import extractor_settings
from shockcal.study.validate import load_config

REPO = Path(__file__).resolve().parents[1]
CONFIG = REPO / "config" / "config.yaml"
SHOT = "104S"
N_TRACES = 30
REPEATS = 3
GOAL_MS = 50.0


def simulated_like(n: int, seed: int = 0) -> pd.DataFrame:
    """n two-step traces shaped like the hydrocode's output, in the simulations-table layout."""
    rng = np.random.default_rng(seed)
    t = np.arange(8001) * 0.0005
    traces = []
    for _ in range(n):
        t1 = rng.uniform(0.8, 0.9)
        t2 = t1 + rng.uniform(0.1, 0.3)
        v1, v2 = rng.uniform(50, 130), rng.uniform(60, 150)
        traces.append(v1 * norm.cdf((t - t1) / rng.uniform(0.003, 0.008))
                      + v2 * norm.cdf((t - t2) / rng.uniform(0.02, 0.06)))
    return pd.DataFrame({"run": range(n), "status": "ok", "reason": "", "t_us": [t] * n, "v_m_s": traces})


def ms_per_trace(function, count: int) -> float:
    """Best of REPEATS wall times of `function()`, per trace, in milliseconds."""
    best = min(_seconds(function) for _ in range(REPEATS))
    return 1e3 * best / count


def _seconds(function) -> float:
    start = time.perf_counter()
    function()
    return time.perf_counter() - start


def main() -> None:
    config = load_config(CONFIG)
    traces = simulated_like(N_TRACES)
    settings = extractor_settings(config, SHOT)
    cases = {f"{N_TRACES} simulated-like traces ({SHOT} window)":
             (lambda: features_table(traces, settings), N_TRACES)}
    for shot, spec in config["observed"]["records"].items():
        t, v = read_record(REPO / spec["path"])
        shot_settings = extractor_settings(config, shot)
        cases[f"measured record {shot} ({len(t)} points)"] = (
            lambda t=t, v=v, s=shot_settings: extract_features(t, v, s), 1)
    features_table(traces.head(1), settings)  # warm-up: imports, first fit
    print(f"load average at start: {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores (timings inflated when high)")
    print(f"{'':45}{'ms/trace':>10}{'1 thread':>10}   goal {GOAL_MS:.0f}")
    for name, (function, count) in cases.items():
        default = ms_per_trace(function, count)
        with threadpool_limits(1):
            single = ms_per_trace(function, count)
        print(f"{name:45}{default:10.1f}{single:10.1f}")
    print(f"load average at end: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
