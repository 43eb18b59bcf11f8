"""`make verify`'s workflow (workflow/rules/verify.smk): the run set verify planned by dry runs, outside `all`."""

from __future__ import annotations

import subprocess

from test_workflow import REPO, job_counts, overlay, snakemake

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
    assert "--n-runs 25 --stream verify" in out and "shockcal verify --design" in out
    assert "--features 104S=" in out and " 105S=" in out and " 106S=" in out
    every = job_counts(snakemake("all", "--dry-run", config_files=[config]).stdout)
    assert not any("verify" in rule for rule in every)


def test_make_verify_runs_the_verify_target_of_the_study():
    printed = subprocess.run(["make", "-n", "-o", ".venv/.installed", "verify", "STUDY=paper"], cwd=REPO,
                             capture_output=True, text=True, check=True).stdout
    assert "--cores" in printed and " verify " in printed.replace("\\\n", " ")
