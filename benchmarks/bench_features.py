"""Feature extraction speed: milliseconds per trace, printed, never asserted (goal: 20 ms/trace).

Times `features_table` (the `shockcal features` code path: the mixture fitted to the exact CDF) on 30
simulated-like traces (two-step Gaussian-CDF traces with varied arrival, plateaus and rise widths on
the 0.5 ns grid of a 4 us run, 8001 points) and `extract_features` on the three measured records
shipped in data/al5083, after a warm-up (numba's kernels load from its cache once a process), with
the default thread pools and with one thread. In the same run, the old fit for comparison:
`extract(..., method="pit")`, scikit-learn's EM on the 10,000 PIT samples, timed once on the first
`N_OLD` traces (it takes 0.3-3 s a trace). CPU seconds are printed beside wall time: on a shared
machine wall time is inflated by the load average, which is printed with them.
"""

from __future__ import annotations

import os
import time
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.stats import norm
from threadpoolctl import threadpool_limits

from shockcal.study.adapters import extractor_settings
from shockcal.study.validate import load_config
from shockcal.velocimetry.feature_tables import features_table
from shockcal.velocimetry.features import extract, extract_features
from shockcal.velocimetry.records import read_record

REPO = Path(__file__).resolve().parents[1]
CONFIG = REPO / "config" / "config.yaml"
SHOT = "104S"
N_TRACES = 30
N_OLD = 5
REPEATS = 3
GOAL_MS = 20.0


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


def ms_per_trace(function, count: int, repeats: int = REPEATS) -> tuple[float, float]:
    """Best of `repeats` (wall, CPU) times of `function()`, per trace, in milliseconds."""
    best = min((_seconds(function) for _ in range(repeats)), key=lambda pair: pair[0])
    return 1e3 * best[0] / count, 1e3 * best[1] / count


def _seconds(function) -> tuple[float, float]:
    start, cpu = time.perf_counter(), time.process_time()
    function()
    return time.perf_counter() - start, time.process_time() - cpu


def old_fit(traces: list, settings) -> None:
    for t, v in traces:
        extract(t, v, settings, method="pit")


def main() -> None:
    config = load_config(CONFIG)
    traces = simulated_like(N_TRACES)
    settings = extractor_settings(config, SHOT)
    cases = {f"{N_TRACES} simulated-like traces ({SHOT} window)":
             (lambda: features_table(traces, settings), N_TRACES,
              lambda: old_fit(list(zip(traces["t_us"], traces["v_m_s"]))[:N_OLD], settings), N_OLD)}
    for shot, spec in config["observed"]["records"].items():
        t, v = read_record(REPO / spec["path"])
        shot_settings = extractor_settings(config, shot)
        cases[f"measured record {shot} ({len(t)} points)"] = (
            lambda t=t, v=v, s=shot_settings: extract_features(t, v, s), 1,
            lambda t=t, v=v, s=shot_settings: old_fit([(t, v)], s), 1)
    features_table(traces.head(1), settings)  # warm-up: imports, kernels from numba's cache, first fit
    old_fit(list(zip(traces["t_us"], traces["v_m_s"]))[:1], settings)
    print(f"load average at start: {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores (timings inflated when high)")
    print(f"{'ms per trace (wall / CPU)':45}{'new':>14}{'new, 1 thread':>16}{'old (PIT 10,000)':>20}"
          f"{'old / new':>11}   goal {GOAL_MS:.0f}")
    for name, (function, count, old, old_count) in cases.items():
        default = ms_per_trace(function, count)
        with threadpool_limits(1):
            single = ms_per_trace(function, count)
        before = ms_per_trace(old, old_count, repeats=1)
        print(f"{name:45}{default[0]:7.1f} /{default[1]:5.1f}{single[0]:9.1f} /{single[1]:5.1f}"
              f"{before[0]:12.0f} /{before[1]:6.0f}{before[0] / default[0]:10.0f}x")
    print(f"load average at end: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
