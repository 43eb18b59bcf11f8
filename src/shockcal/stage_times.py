"""Wall and CPU seconds per workflow stage, from Snakemake's benchmark files (`benchmark:` of each rule).

Each rule writes `{results}/benchmarks/<rule>.tsv`, `<rule>/<job>.tsv` or, for the rules of a run set
(training, predict, check), `<run set>/<rule>/.../<job>.tsv` (columns `s` = wall seconds and `cpu_time`
= CPU seconds, among others). This sums them per stage: the top directory, or the top two where the
files lie deeper (a run set's rule), so a study can print where its time went (`make study` does, and
the README keeps the table).
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd


def stage_table(benchmarks: Path) -> pd.DataFrame:
    """One row per stage: jobs, summed wall and CPU seconds, the longest job's wall seconds; then a total."""
    rows = []
    for tsv in sorted(Path(benchmarks).rglob("*.tsv")):
        bench = pd.read_csv(tsv, sep="\t")
        parts = tsv.relative_to(benchmarks).parts
        stage = "/".join(parts[:2]) if len(parts) > 2 else Path(parts[0]).stem
        rows.append({"stage": stage, "wall_s": float(bench["s"].iloc[-1]), "cpu_s": float(bench["cpu_time"].iloc[-1])})
    if not rows:
        return pd.DataFrame(columns=["stage", "jobs", "wall_s", "cpu_s", "longest_job_s"])
    jobs = pd.DataFrame(rows)
    table = jobs.groupby("stage", sort=False).agg(jobs=("wall_s", "size"), wall_s=("wall_s", "sum"),
                                                  cpu_s=("cpu_s", "sum"), longest_job_s=("wall_s", "max"))
    table.loc["total"] = [len(jobs), jobs["wall_s"].sum(), jobs["cpu_s"].sum(), jobs["wall_s"].max()]
    return table.reset_index().round(1)
