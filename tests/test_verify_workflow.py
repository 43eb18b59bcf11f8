"""`make verify`'s workflow (workflow/rules/verify.smk): the run set verify planned by dry runs, outside `all`, and
run on the quick study (slow)."""

from __future__ import annotations

import subprocess

import numpy as np
import pandas as pd
import pytest
from test_workflow import REPO, job_counts, overlay, pending_jobs, snakemake, unread_keys

SHOTS = 3


def test_verify_runs_n_draws_posterior_draws_per_shot_through_the_simulate_rules(tmp_path):
    """verify.n_draws = 25 in chunks of simulate.chunk_size 10: three hydrocode chunks per shot, their features, the
    draws from the joint posterior (stream verify) and one verdict; nothing of it in `all`."""
    config = overlay(tmp_path / "verify.yaml", study={"results_dir": str(tmp_path / "results")},
                     verify={"n_draws": 25})
    out = snakemake("verify", "--dry-run", "--printshellcmds", config_files=[config]).stdout
    jobs = job_counts(out)
    assert jobs["simulate[verify]"] == SHOTS * 3 and jobs["features_chunk[verify]"] == SHOTS * 3
    assert jobs["features[verify]"] == SHOTS
    assert jobs["verify_design"] == jobs["verify"] == 1
    assert jobs["calibrate"] == 1                                # the joint posterior only
    assert "simulate[predict]" not in jobs
    assert "--stream verify --out" in out and "shockcal verify --design" in out
    assert "--features 104S=" in out and " 105S=" in out and " 106S=" in out
    every = job_counts(snakemake("all", "--dry-run", config_files=[config]).stdout)
    assert not any("verify" in rule for rule in every)


def test_make_verify_runs_the_verify_target_of_the_study():
    printed = subprocess.run(["make", "-n", "-o", ".venv/.installed", "verify", "STUDY=paper"], cwd=REPO,
                             capture_output=True, text=True, check=True).stdout
    assert "--cores" in printed and " verify " in printed.replace("\\\n", " ")


@pytest.mark.slow
def test_verify_target_on_the_quick_study(quick_study, tmp_path):
    """`snakemake verify` on the quick study with verify.n_draws 25: the draws run at every shot, the verdict with
    k-hat and the emulator's error at the draws (per feature, in m/s and in the records' sds, and in the summary);
    every key the verify stages declare is read by their jobs; `all` untouched."""
    results, config = quick_study
    draws = overlay(tmp_path / "draws.yaml", verify={"n_draws": 25})
    reads = tmp_path / "reads"
    snakemake("verify", "--cores", "2", config_files=[config, draws], read_log=reads)
    summary = pd.read_csv(results / "verify" / "summary.csv")
    error = pd.read_csv(results / "verify" / "emulator_error.csv")
    assert summary["n_draws"].iloc[0] == 25 and len(error) == 3 * 4 + 1    # 4 features of 3 shots, and over all
    assert summary["parameter"].str.endswith(("_MPa", "_GPa", "_m_s")).sum() >= 5
    assert np.isfinite(summary["khat"]).all() and summary["passed"].iloc[0] == (summary["khat"] <= summary[
        "khat_threshold"]).iloc[0]
    overall = error.iloc[-1]
    assert overall["feature"] == "all (25 runs)" and (error["rmse_m_s"] > 0).all()
    assert summary["emulator_rmse_m_s"].iloc[0] == pytest.approx(overall["rmse_m_s"])
    assert summary["emulator_rmse_records_sd"].iloc[0] == pytest.approx(
        np.sqrt(np.mean(error["rmse_records_sd"].iloc[:-1] ** 2)))
    log = (results / "logs" / "verify" / "summary.log").read_text()
    assert "k-hat" in log and "records' sds" in log and "Traceback" not in log
    assert pending_jobs(config) == {}
    unread, stages = unread_keys(reads)
    assert {"verify_design", "verify"} <= stages and not unread, f"declared and never read (stage: keys): {unread}"
