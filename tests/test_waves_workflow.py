"""A sequential study's workflow (design.strategy: waves, config/sequential-quick.yaml over config/quick.yaml):
its DAG per wave count (dry runs), and on one run of the toy study: nothing to redo, a study killed in wave 2
(its outputs from wave 2 on missing) resumes at wave 2, an extractor change reruns no hydrocode of wave 0 and
re-places the later waves, and a settled posterior stops the study with an empty wave."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest
import yaml
from test_workflow import job_counts, overlay, pending_jobs, snakemake, unread_keys

REPO = Path(__file__).resolve().parents[1]
SEQUENTIAL = REPO / "config" / "sequential-quick.yaml"
SHOTS = 3


def waves_overlay(path: Path, results: Path, max_runs: int = 50, **waves) -> Path:
    return overlay(path, study={"results_dir": str(results)},
                   design={"waves": {"initial_runs": 30, "runs_per_wave": 10, "max_runs": max_runs, **waves}})


@pytest.fixture(scope="module")
def two_wave_dry_run(tmp_path_factory) -> str:
    """The output of a dry run of the toy sequential study (max_runs 50: waves 1 and 2) into a fresh results
    directory, run once for the two tests that read its plan (job counts, priorities)."""
    root = tmp_path_factory.mktemp("two-waves")
    config = waves_overlay(root / "waves.yaml", root / "results")
    return snakemake("all", "--dry-run", config_files=[SEQUENTIAL, config]).stdout


@pytest.mark.parametrize("max_runs, waves", [(30, 0), (50, 2)])
def test_each_wave_is_a_run_set_with_its_refit_and_recalibration(tmp_path, max_runs, waves, request):
    if max_runs == 50:          # waves_overlay's default: the module's dry run
        jobs = job_counts(request.getfixturevalue("two_wave_dry_run"))
    else:
        jobs = pending_jobs(SEQUENTIAL, waves_overlay(tmp_path / "waves.yaml", tmp_path / "results", max_runs))
    assert jobs["simulate"] == SHOTS * 3                      # wave 0: the training run set, 30 runs in chunks of 10
    for k in range(1, waves + 1):
        assert jobs[f"simulate[wave{k}]"] == SHOTS             # 10 runs: one chunk per shot
        assert jobs[f"features[wave{k}]"] == SHOTS
    assert f"simulate[wave{waves + 1}]" not in jobs
    assert jobs.get("wave_design", 0) == waves
    assert jobs.get("wave_emulator", 0) == jobs.get("wave_calibrate", 0) == waves   # the steps before the last
    assert jobs.get("merge_runs", 0) == (waves + 1 if waves else 0)
    assert jobs["emulator"] == 1 and jobs["calibrate"] == SHOTS + 1                  # the study's, on every run


def test_each_run_sets_longest_hydrocode_chunk_starts_first(two_wave_dry_run):
    """105S (the thickest target, the longest record) costs 1.9 times 104S's per run: its chunk of each wave
    gets the highest priority, so it does not start last and leave a core idle."""
    out = two_wave_dry_run
    priority = {}
    for block in re.split(r"^(?=(?:local)?rule \S+:$)", out, flags=re.MULTILINE)[1:]:
        if re.match(r"(?:local)?rule simulate:", block):
            run_set, shot, chunk = re.search(r"run_set=(\w+), shot=(\w+), chunk=(\d+)", block).groups()
            priority[run_set, shot, int(chunk)] = int(re.search(r"^\s+priority: (\d+)$", block, re.MULTILINE).group(1))
    for run_set in ["wave1", "wave2", "predict"]:
        chunks = {shot: p for (rs, shot, _), p in priority.items() if rs == run_set}
        assert max(chunks, key=chunks.get) == "105S" and chunks["105S"] > max(chunks["104S"], chunks["106S"]), chunks
    assert max(priority.values()) < 10                     # below the joint calibration's


@pytest.fixture(scope="module")
def sequential(tmp_path_factory):
    """The toy sequential study run once: (results directory, its config overlay)."""
    root = tmp_path_factory.mktemp("sequential")
    config = waves_overlay(root / "results.yaml", root / "results")
    snakemake("all", "--cores", "2", config_files=[SEQUENTIAL, config], read_log=root / "reads")
    return root / "results", config


@pytest.mark.slow
def test_the_waves_stages_read_every_key_they_declare(sequential):
    """The stages only a sequential study runs (wave designs, merged runs, the lighter step calibrations), as the
    quick study's in test_workflow: a declared key none of their jobs read would rerun them for nothing."""
    unread, stages = unread_keys(sequential[0].parent / "reads")
    assert not unread, f"declared and never read (stage: keys): {unread}"
    assert {"wave_design", "merge_runs", "emulate", "calibrate"} <= stages, stages


@pytest.mark.slow
def test_the_study_uses_every_wave(sequential):
    results, config = sequential
    assert pending_jobs(SEQUENTIAL, config) == {}
    runs = pd.read_parquet(results / "waves" / "step2" / "design.parquet")
    assert runs["run"].tolist() == list(range(50))
    emulated = pd.read_parquet(results / "emulator" / "cv.parquet")
    assert sorted(emulated["run"].unique()) == list(range(50))       # the study's emulator: every wave's runs


@pytest.mark.slow
def test_a_study_killed_in_wave_2_resumes_at_wave_2(sequential):
    results, config = sequential
    for path in (results / "wave2", results / "waves" / "step2", results / "emulator"):
        shutil.rmtree(path)
    jobs = pending_jobs(SEQUENTIAL, config)
    assert jobs["wave_design"] == 1
    assert {key for key in jobs if key.startswith("simulate")} == {"simulate[wave2]", "simulate[predict]"}
    assert "wave_emulator" not in jobs and "wave_calibrate" not in jobs
    snakemake("all", "--cores", "2", config_files=[SEQUENTIAL, config])
    assert pending_jobs(SEQUENTIAL, config) == {}


@pytest.mark.slow
def test_an_extractor_change_reruns_no_wave_0_hydrocode_and_re_places_the_later_waves(sequential, tmp_path):
    results, config = sequential
    extractor = overlay(tmp_path / "extractor.yaml", features={"n_samples": 1500})
    jobs = pending_jobs(SEQUENTIAL, config, extractor)
    assert "simulate" not in jobs and jobs["features_chunk"] == SHOTS * 3          # wave 0: features only
    assert jobs["wave_design"] == 2 and jobs["simulate[wave1]"] == jobs["simulate[wave2]"] == SHOTS
    assert jobs["wave_emulator"] == jobs["wave_calibrate"] == 2 and jobs["emulator"] == 1


@pytest.mark.slow
def test_a_settled_posterior_stops_the_study_with_an_empty_wave(sequential, tmp_path):
    results, config = sequential
    effective = yaml.safe_load(next((results / "config").glob("effective-*.yaml")).read_text())
    effective["design"]["waves"]["stop_mcse"] = 1e9          # every posterior counts as settled
    merged = tmp_path / "config.yaml"
    merged.write_text(yaml.safe_dump(effective))
    step = results / "waves"
    out = tmp_path / "wave2.parquet"
    subprocess.run([sys.executable, "-m", "shockcal", "wave-design", "--config", str(merged), "--wave", "2",
                    "--posterior", str(step / "step1" / "posterior" / "joint.parquet"),
                    "--earlier-summary", str(step / "step0" / "posterior" / "joint_summary.parquet"),
                    "--previous-design", str(results / "wave1" / "design.parquet"),
                    "--runs", str(step / "step1" / "design.parquet"), "--out", str(out)], cwd=REPO, check=True)
    assert pd.read_parquet(out).empty
    for shot in ("104S", "105S", "106S"):
        traces, features = tmp_path / f"{shot}-sim.parquet", tmp_path / f"{shot}-features.parquet"
        for command in (["simulate", "--shot", shot, "--design", str(out), "--rows", "0:10", "--out", str(traces)],
                        ["features", "--shot", shot, "--traces", str(traces), "--out", str(features)]):
            subprocess.run([sys.executable, "-m", "shockcal", *command, "--allow-empty", "--config", str(merged)],
                           cwd=REPO, check=True)
        assert pd.read_parquet(features).empty


@pytest.mark.slow
def test_a_shot_added_to_a_finished_study_reruns_no_wave(sequential, tmp_path):
    """Adding a shot (design.new_shots) rewrites the training design with the shot's input columns and gives the
    base observed features a config of their own; neither reruns a wave, a step or the base shots' features.
    What runs is the last step's base emulator and joint posterior (they place the shot's runs), its own runs,
    and the study's four-shot emulator and joint posterior; without the shot again, nothing."""
    from test_new_shots import shot_overlay

    results, config = sequential
    shot = shot_overlay(tmp_path, results)
    jobs = pending_jobs(SEQUENTIAL, config, shot, target=str(results / "posterior" / "joint.parquet"))
    assert set(jobs) == {"observed", "wave_emulator", "wave_calibrate", "new_shot_design", "simulate[new_shot]",
                         "features_chunk[new_shot]", "features[new_shot]", "emulator", "calibrate"}, jobs
    assert jobs["wave_emulator"] == jobs["wave_calibrate"] == jobs["calibrate"] == 1
    assert pending_jobs(SEQUENTIAL, config) == {}
