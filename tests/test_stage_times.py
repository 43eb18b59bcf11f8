"""The per-stage time table sums Snakemake's benchmark files per rule."""

from __future__ import annotations

from shockcal.stage_times import stage_table

HEADER = "s\th:m:s\tmax_rss\tmax_vms\tmax_uss\tmax_pss\tio_in\tio_out\tmean_load\tcpu_time\n"


def test_stage_table_sums_jobs_per_rule(tmp_path):
    (tmp_path / "simulate" / "104S").mkdir(parents=True)
    for k, (wall, cpu) in enumerate([(10.0, 9.0), (30.0, 25.0)]):
        (tmp_path / "simulate" / "104S" / f"chunk-{k}.tsv").write_text(HEADER + f"{wall}\t0:00:10\t1\t1\t1\t1\t0\t0\t1\t{cpu}\n")
    (tmp_path / "design.tsv").write_text(HEADER + "2.5\t0:00:02\t1\t1\t1\t1\t0\t0\t1\t2.0\n")
    table = stage_table(tmp_path).set_index("stage")
    assert table.loc["simulate", ["jobs", "wall_s", "cpu_s", "longest_job_s"]].tolist() == [2, 40.0, 34.0, 30.0]
    assert table.loc["design", "wall_s"] == 2.5
    assert table.loc["total", ["jobs", "wall_s", "cpu_s"]].tolist() == [3, 42.5, 36.0]
