"""`make bench`: every benchmarks/bench_*.py in turn, each in its own process, with progress and time left.

A line per benchmark before it starts ("[2/6] bench_emulator.py, 1 min 10 s so far, about 3 min left"),
the estimate from the benchmarks' own typical costs on this machine (TYPICAL_S, measured 2026-11-25
and refined by what the finished ones took), then the benchmark's own output. Stops at the first that
fails, with its exit code.
"""

from __future__ import annotations

import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
TYPICAL_S = {"bench_calibration.py": 150, "bench_command_simulator.py": 15, "bench_emulator.py": 60,
             "bench_features.py": 40, "bench_hydro.py": 30, "bench_likelihood.py": 170,
             "bench_rate_sensitivity.py": 20}   # seconds on 2 idle cores; unknown ones count 60


def _duration(seconds: float) -> str:
    return f"{int(seconds // 60)} min {int(seconds % 60)} s" if seconds >= 60 else f"{seconds:.0f} s"


def main() -> int:
    benches = sorted(HERE.glob("bench_*.py"))
    start, spent_typical = time.perf_counter(), 0.0
    for k, bench in enumerate(benches, 1):
        elapsed = time.perf_counter() - start
        typical = [TYPICAL_S.get(b.name, 60) for b in benches]
        pace = elapsed / spent_typical if spent_typical else 1.0          # this machine today against typical
        left = pace * sum(typical[k - 1:])
        print(f"== [{k}/{len(benches)}] {bench.name}, {_duration(elapsed)} so far, about {_duration(left)} left", flush=True)
        done = subprocess.run([sys.executable, str(bench)])
        if done.returncode:
            return done.returncode
        spent_typical += typical[k - 1]
    print(f"== all {len(benches)} benchmarks in {_duration(time.perf_counter() - start)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
