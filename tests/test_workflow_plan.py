"""The workflow's plan (shockcal.study.workflow_plan) without snakemake: run sets and their chunks, the chunks'
row digests, priorities, a sequential study's waves and their designs' inputs, new shots, the next-shot check's
studies and models, the figure targets, and the files written when the workflow is read. The rules that use it
are checked end to end by dry runs (tests/test_workflow.py, tests/test_new_shots.py, tests/test_waves_workflow.py)."""

from __future__ import annotations

import shutil
from pathlib import Path
from types import SimpleNamespace

import pandas as pd
import pytest
import yaml
from snakemake.io import is_flagged

from shockcal.errors import InputError
from shockcal.study.stages import stage_config
from shockcal.study.validate import load_config
from shockcal.study.workflow_plan import (
    check_requested,
    design_digests,
    existing_coverage,
    figure_targets,
    pairs,
    plan_next_shot_check,
    plan_next_shot_check_or_exit,
    plan_workflow,
    record_paths,
    write_planned_files,
)

REPO = Path(__file__).resolve().parents[1]


def study(tmp_path: Path, name: str = "quick.yaml", **sections) -> dict:
    """config/`name` with `sections` over it, its results under tmp_path/results."""
    overlay = tmp_path / "overlay.yaml"
    sections["study"] = {"results_dir": str(tmp_path / "results"), **sections.get("study", {})}
    overlay.write_text(yaml.safe_dump({"extends": str(REPO / "config" / name), **sections}))
    return load_config(overlay)


def with_new_shot(tmp_path: Path, name: str = "quick.yaml") -> dict:
    """The study with a fourth shot 107S (106S's plates, inputs V4 and Delta4 of its own, its own record)."""
    paper = load_config(REPO / "config" / "config.yaml")
    record = tmp_path / "Data_S107S.txt"
    shutil.copy(REPO / paper["observed"]["records"]["106S"]["path"], record)
    shot = dict(paper["shots"]["106S"], velocity_input="V4", shear_modulus_inputs=["G1", "Delta4"])
    return study(tmp_path, name, inputs={"V4": paper["inputs"]["V3"], "Delta4": paper["inputs"]["Delta3"]},
                 shots={"107S": shot}, observed={"records": {"107S": {**paper["observed"]["records"]["106S"],
                                                                       "path": str(record)}}})


def test_run_sets_and_their_chunks(tmp_path):
    plan = plan_workflow(study(tmp_path))
    assert list(plan.run_set_sizes) == ["training", "predict", "check", "check_posterior", "next_shot", "verify",
                                        "next_shot_check", "next_shot_truth", "new_shot"]
    assert plan.run_set_sizes["training"] == 40 and plan.run_set_chunks["training"] == [0, 1, 2, 3]
    assert plan.run_set_chunks["predict"] == [0] and plan.run_set_chunks["next_shot"] == [0, 1]
    # a new shot's 20 runs in NEW_SHOT_CHUNKS = 4 chunks of 5, not one of simulate.chunk_size 10
    assert plan.run_set_chunk_size["new_shot"] == 5 and plan.run_set_chunks["new_shot"] == [0, 1, 2, 3]
    assert plan.chunk_rows("training", "3") == "30:40"
    # a check candidate's design is the training design (40 rows) cut at next_shot.check.n_training_runs
    small = plan_workflow(study(tmp_path, simulate={"chunk_size": 15}, next_shot={"check": {"n_training_runs": 20}}))
    assert small.chunk_rows("next_shot_check", 1) == "15:20" and small.chunk_rows("training", 1) == "15:30"
    assert plan.waves == [] and plan.last_step == 0 and plan.wave_run_sets == ["training"]


def test_a_sequential_studys_waves_and_their_designs_inputs(tmp_path):
    plan = plan_workflow(study(tmp_path, "sequential.yaml"))
    results = tmp_path / "results"
    assert plan.waves == ["wave1", "wave2"] and plan.last_step == 2
    assert plan.run_set_sizes["training"] == 150 and plan.run_set_sizes["wave1"] == plan.run_set_sizes["wave2"] == 75
    assert plan.allow_empty("wave2") == "--allow-empty" and plan.allow_empty("training") == ""
    first = plan.wave_design_inputs(1)
    assert "earlier" not in first
    assert first["previous"] == f"{results}/training/design.parquet" and is_flagged(first["previous"], "ancient")
    second = plan.wave_design_inputs("2")
    assert second["earlier"] == f"{results}/waves/step0/posterior/joint_summary.parquet"
    assert second["posterior"] == f"{results}/waves/step1/posterior/joint.parquet"
    assert second["emulator"] == f"{results}/waves/step1/emulator/emulator.json"
    assert second["previous"] == f"{results}/wave1/design.parquet" and not is_flagged(second["previous"], "ancient")
    assert second["observed"] == f"{results}/features/observed_base.parquet"
    assert plan.step_features(1) == [f"{results}/{run_set}/features/{shot}.parquet"
                                     for run_set in ("training", "wave1") for shot in ("104S", "105S", "106S")]
    runs = plan.study_runs()
    assert runs["design"] == f"{results}/waves/step2/design.parquet" and runs["shot_designs"] == []
    assert runs["features"][0] == f"{results}/waves/step2/features/104S.parquet"


def test_chunk_digests_follow_a_shots_own_rows_and_columns(tmp_path):
    config = study(tmp_path)
    plan = plan_workflow(config)
    digests = plan.chunk_digests["104S"]
    assert len(digests) == 4 and len(set(digests)) == 4
    grown = plan.design.assign(V4=0.1)  # another shot's column leaves 104S's chunks alone
    assert design_digests(grown, config, "104S", 10) == digests
    changed = plan.design.copy()
    changed.loc[25, "V1"] *= 1.01  # a row of chunk 2 read by 104S (its impact velocity)
    assert [a == b for a, b in zip(design_digests(changed, config, "104S", 10), digests)] == [True, True, False, True]
    assert plan.rows_digest("training", "105S", "1") == plan.chunk_digests["105S"][1]
    assert plan.rows_digest("predict", "105S", "0") == ""


def test_the_costliest_chunks_start_first(tmp_path):
    """Priority 5 + 4 x (the chunk's cost / the run set's longest): 105S's thicker target costs most."""
    plan = plan_workflow(study(tmp_path, simulate={"chunk_size": 15}))
    assert [plan.simulate_priority("training", "105S", chunk) for chunk in (0, 1, 2)] == [9, 9, 8]   # 15, 15, 10 rows
    assert plan.simulate_priority("training", "104S", 0) == plan.simulate_priority("training", "106S", 0) == 7
    assert plan.simulate_priority("predict", "104S", 0) == 8   # the predictive runs' end time: a smaller gap
    assert plan.simulate_priority("next_shot", plan.candidates[0], 0) == 5


def test_each_run_sets_design(tmp_path):
    plan = plan_workflow(study(tmp_path))
    results = tmp_path / "results"
    training = plan.design_input("training", "104S")
    assert training == f"{results}/training/design.parquet" and is_flagged(training, "ancient")
    assert plan.design_input("predict", "104S") == f"{results}/predict/design.parquet"
    candidate = plan.candidates[0]
    assert plan.design_input("next_shot", candidate) == f"{results}/next_shot/designs/{candidate}.parquet"
    assert plan.design_input("next_shot_truth", candidate) == f"{results}/next_shot_truth/designs/{candidate}.parquet"
    assert plan.design_input("next_shot_truth", "104S") == f"{results}/next_shot_truth/design.parquet"
    # a candidate reads its candidate stage's slice (its own plates), a shot its own
    assert plan.stage_settings("simulate", "104S") == stage_config(plan.config, "simulate", "104S")
    assert plan.stage_settings("simulate", candidate) == stage_config(plan.config, "next_shot_simulate", candidate)


def test_a_new_shot_runs_on_its_own_and_the_base_study_leaves_it_out(tmp_path):
    plan = plan_workflow(with_new_shot(tmp_path))
    results = tmp_path / "results"
    assert plan.new_shots == ["107S"] and plan.base_shots == ["104S", "105S", "106S"]
    assert list(plan.base_study["shots"]) == plan.base_shots
    assert plan.training_run_set("107S") == "new_shot" and plan.training_run_set("104S") == "training"
    runs = plan.study_runs()
    assert runs["features"][-1] == f"{results}/new_shot/features/107S.parquet"
    assert runs["shot_designs"] == [f"{results}/new_shot/designs/107S.parquet"]
    assert runs["design"] == f"{results}/training/design.parquet"
    assert plan.base_config_option.startswith(f"--config {results}/config/base-")
    assert record_paths(plan.base_study) == record_paths(plan.config)[:3]
    assert plan_workflow(study(tmp_path)).base_config_option == ""


def test_the_planned_files_are_written_once_each(tmp_path):
    plan = plan_workflow(with_new_shot(tmp_path))
    write_planned_files(plan)
    effective = Path(plan.effective_config)
    assert effective.parent == tmp_path / "results" / "config" and effective.name.startswith("effective-")
    assert yaml.safe_load(effective.read_text()) == plan.config
    base = Path(plan.base_config_option.removeprefix("--config "))
    assert list(yaml.safe_load(base.read_text())["shots"]) == ["104S", "105S", "106S"]
    design = Path(plan.design_path)
    assert pd.read_parquet(design)["run"].tolist() == plan.design["run"].tolist()
    before = {path: path.stat().st_mtime_ns for path in (effective, base, design)}
    write_planned_files(plan_workflow(with_new_shot(tmp_path)))   # the same study read again: nothing rewritten
    assert {path: path.stat().st_mtime_ns for path in before} == before
    other = plan_workflow(study(tmp_path, calibration={"n_live": 300}))
    assert other.effective_config != plan.effective_config   # another config, another file: running jobs keep theirs


def test_the_check_is_asked_for_by_its_rule_or_its_files():
    assert check_requested(["next_shot_check", "--configfile", "config/quick.yaml"])
    assert check_requested(["results/quick/next_shot/check_summary.csv"])
    assert not check_requested(["next_shot", "--configfile", "config/quick.yaml"])
    assert not check_requested(["all"])


def test_the_next_shot_checks_studies(tmp_path):
    plan = plan_workflow(study(tmp_path))
    write_planned_files(plan)
    assert plan_next_shot_check(plan, required=False).check_plans == {}   # no ranking yet, not asked for
    with pytest.raises(InputError, match=r"next_shot/ranking\.csv: missing"):
        plan_next_shot_check(plan, required=True)
    with pytest.raises(SystemExit, match=r"^shockcal: error: .*ranking\.csv: missing"):
        plan_next_shot_check_or_exit(plan, ["next_shot_check"])
    worst, best = plan.candidates
    ranking = tmp_path / "results" / "next_shot" / "ranking.csv"
    ranking.parent.mkdir(parents=True)
    ranking.write_text(f"candidate,eig_nats\n{worst},0.5\n{best},1.5\n")
    checked = plan_next_shot_check(plan, required=True)
    assert list(checked.check_plans) == [best, worst] and checked.check_models() == ["baseline", best, worst]
    assert checked.check_model_shots(best) == ["104S", "105S", "106S", best]
    assert checked.check_model_shots("baseline") == ["104S", "105S", "106S"]
    assert checked.check_model_config_option("baseline") == ""
    assert checked.check_model_config_option(best) == f"--config {checked.check_plans[best]['config']}"
    assert Path(checked.check_plans[best]["config"]).is_file() and Path(checked.check_plans[best]["design"]).is_file()
    assert checked.check_model_study(best)["shots"][best] and checked.check_model_study("baseline") is plan.config
    inputs = checked.check_emulator_inputs(best)
    assert inputs["design"] == checked.check_plans[best]["design"]
    assert inputs["features"][-1] == f"{tmp_path}/results/next_shot_check/features/{best}.parquet"
    assert checked.check_emulator_inputs("baseline")["design"] == plan.design_path
    design = checked.design_input("next_shot_check", best)
    assert design == checked.check_plans[best]["design"] and is_flagged(design, "ancient")
    assert len(checked.check_digests[best]) == 4   # the derived design's 40 rows, in chunks of 10
    assert checked.rows_digest("next_shot_check", best, 1) == checked.check_digests[best][1]


def test_figure_targets_leave_out_what_an_archive_study_cannot_make(tmp_path):
    plan = plan_workflow(study(tmp_path))
    specs = {"a": SimpleNamespace(target="all", needs=["observed", "simulations:104S"]),
             "b": SimpleNamespace(target="all", needs=["posterior:joint"]),
             "c": SimpleNamespace(target="next_shot", needs=["next_shot_ranking"])}
    figures = tmp_path / "results" / "figures"
    in_all, others = figure_targets(plan, specs, ["png", "pdf"])
    assert in_all == [f"{figures}/a.png", f"{figures}/a.pdf", f"{figures}/b.png", f"{figures}/b.pdf"]
    assert others == {"next_shot": [f"{figures}/c.png", f"{figures}/c.pdf"]}
    archive, _ = figure_targets(SimpleNamespace(results=plan.results, archive=True), specs, ["png"])
    assert archive == [f"{figures}/b.png"]


def test_existing_coverage_tables_and_pairs(tmp_path):
    there, missing = tmp_path / "coverage_emulator.parquet", tmp_path / "coverage_hydrocode.parquet"
    there.write_text("x")
    found = existing_coverage(["emulator", "hydrocode"], [str(there), str(missing)])
    assert found["pairs"] == f"emulator={there}"
    assert found["modified"][0] == int(there.stat().st_mtime) and found["modified"][1] is None
    assert existing_coverage(["hydrocode"], [str(missing)])["pairs"] == ""
    assert pairs(["104S", "105S"], ["a.parquet", "b.parquet"]) == "104S=a.parquet 105S=b.parquet"
