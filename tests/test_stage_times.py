"""The per-stage time table sums Snakemake's benchmark files per rule."""

from __future__ import annotations

from shockcal.stage_times import stage_table

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
