"""Wall and CPU seconds per workflow stage, from Snakemake's benchmark files (`benchmark:` of each rule).

Each rule writes `{results}/benchmarks/<rule>.tsv`, `<rule>/<job>.tsv` or, for the rules of a run set
(training, predict, check), `<run set>/<rule>/.../<job>.tsv` (columns `s` = wall seconds and `cpu_time`
= CPU seconds, among others). This sums them per stage: the top directory, or the top two where the
files lie deeper (a run set's rule), so a study can print where its time went (`make study` does, and
the README keeps the table).

`simulate_overhead` reads each simulate job's start-up and write-out: its benchmark wall seconds minus
the hydrocode seconds of its runs (`wall_time_s` in the chunk it wrote), in seconds and as a share of
the job (the per-job overhead goal: under 2%).
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd


def stage_table(benchmarks: Path) -> pd.DataFrame:
    """One row per stage: jobs, summed wall and CPU seconds, the longest job's wall seconds; then a total."""
    rows = []
    for tsv in sorted(Path(benchmarks).rglob("*.tsv")):
        bench = job_benchmark(tsv)
        parts = tsv.relative_to(benchmarks).parts
        stage = "/".join(parts[:2]) if len(parts) > 2 else Path(parts[0]).stem
        rows.append({"stage": stage, "wall_s": float(bench["s"]), "cpu_s": float(bench["cpu_time"])})
    if not rows:
        return pd.DataFrame(columns=["stage", "jobs", "wall_s", "cpu_s", "longest_job_s"])
    jobs = pd.DataFrame(rows)
    table = jobs.groupby("stage", sort=False).agg(jobs=("wall_s", "size"), wall_s=("wall_s", "sum"),
                                                  cpu_s=("cpu_s", "sum"), longest_job_s=("wall_s", "max"))
    table.loc["total"] = [len(jobs), jobs["wall_s"].sum(), jobs["cpu_s"].sum(), jobs["wall_s"].max()]
    return table.reset_index().round(1)


def simulate_overhead(benchmarks: Path) -> pd.DataFrame:
    """Per run set, over its simulate jobs whose chunk is still in `{results}/<run set>/simulations`
    (`benchmarks` is `{results}/benchmarks`): jobs, the median overhead (job wall s minus its runs'
    hydrocode s) and its share of the job wall, median and range (%)."""
    benchmarks = Path(benchmarks)
    rows = []
    for tsv in sorted(benchmarks.glob("*/simulate/*/chunk-*.tsv")):
        run_set, _, shot, name = tsv.relative_to(benchmarks).parts
        chunk = benchmarks.parent / run_set / "simulations" / shot / f"{Path(name).stem}.parquet"
        if not chunk.is_file():
            continue
        job_s = float(job_benchmark(tsv)["s"])
        hydro_s = float(pd.read_parquet(chunk, columns=["wall_time_s"])["wall_time_s"].sum())
        rows.append({"run_set": run_set, "overhead_s": job_s - hydro_s, "share": (job_s - hydro_s) / job_s})
    if not rows:
        return pd.DataFrame(columns=["run_set", "jobs", "overhead_s", "share_pct", "min_pct", "max_pct"])
    jobs = pd.DataFrame(rows)
    table = jobs.groupby("run_set", sort=False).agg(jobs=("share", "size"), overhead_s=("overhead_s", "median"),
                                                    share_pct=("share", "median"), min_pct=("share", "min"),
                                                    max_pct=("share", "max"))
    table[["share_pct", "min_pct", "max_pct"]] *= 100
    return table.reset_index().round(2)


def job_benchmark(tsv: Path) -> pd.Series:
    """A job's benchmark: the last row of its file (columns `s` = wall seconds, `cpu_time` = CPU seconds)."""
    return pd.read_csv(tsv, sep="\t").iloc[-1]
