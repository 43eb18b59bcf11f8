"""The per-stage time table sums Snakemake's benchmark files per rule."""

from __future__ import annotations

import pandas as pd

from shockcal.study.stage_times import simulate_overhead, stage_table

HEADER = "s\th:m:s\tmax_rss\tmax_vms\tmax_uss\tmax_pss\tio_in\tio_out\tmean_load\tcpu_time\n"


def bench_file(path, wall, cpu):
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(HEADER + f"{wall}\t0:00:10\t1\t1\t1\t1\t0\t0\t1\t{cpu}\n")


def test_stage_table_sums_jobs_per_rule(tmp_path):
    for k, (wall, cpu) in enumerate([(10.0, 9.0), (30.0, 25.0)]):
        bench_file(tmp_path / "training" / "simulate" / "104S" / f"chunk-{k}.tsv", wall, cpu)
    bench_file(tmp_path / "predict" / "simulate" / "104S" / "chunk-0.tsv", 7.0, 6.0)
    bench_file(tmp_path / "predict" / "design.tsv", 1.5, 1.0)
    bench_file(tmp_path / "emulator.tsv", 2.5, 2.0)
    table = stage_table(tmp_path).set_index("stage")
    assert table.loc["training/simulate", ["jobs", "wall_s", "cpu_s", "longest_job_s"]].tolist() == [2, 40.0, 34.0, 30.0]
    assert table.loc["predict/simulate", "wall_s"] == 7.0
    assert table.loc["predict", "wall_s"] == 1.5
    assert table.loc["emulator", "wall_s"] == 2.5
    assert table.loc["total", ["jobs", "wall_s", "cpu_s"]].tolist() == [5, 51.0, 43.0]


def test_simulate_overhead_is_job_wall_minus_its_runs_hydrocode_time(tmp_path):
    benchmarks = tmp_path / "benchmarks"
    for k, (job_s, runs_s) in enumerate([(50.0, [24.0, 25.0]), (20.0, [9.0, 9.0]), (9.0, [8.0])]):
        bench_file(benchmarks / "training" / "simulate" / "104S" / f"chunk-{k}.tsv", job_s, job_s)
        chunks = tmp_path / "training" / "simulations" / "104S"
        chunks.mkdir(parents=True, exist_ok=True)
        pd.DataFrame({"run": range(len(runs_s)), "wall_time_s": runs_s}).to_parquet(chunks / f"chunk-{k}.parquet")
    bench_file(benchmarks / "training" / "simulate" / "104S" / "chunk-3.tsv", 5.0, 5.0)   # its chunk was deleted
    table = simulate_overhead(benchmarks).set_index("run_set")
    assert table.loc["training", "jobs"] == 3
    assert table.loc["training", "overhead_s"] == 1.0                     # median of 1, 2, 1 s
    assert table.loc["training", ["share_pct", "min_pct", "max_pct"]].tolist() == [10.0, 2.0, 11.11]
