"""A shot added to a study (design.new_shots, docs/workflow.md "Adding a shot"): its runs placed from the base
shots' joint posterior with its own inputs drawn fresh, an emulator block of its own, the base jobs' settings
untouched by it, and the workflow's DAG for a Latin-hypercube and a sequential study (dry runs)."""

from __future__ import annotations

import copy
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from test_emulator import _synthetic_study
from test_workflow import _own_record, job_counts, overlay, pending_jobs, snakemake

from shockcal.design.waves import new_shot_design
from shockcal.emulator.study_emulator import fit_emulator
from shockcal.errors import ConfigError
from shockcal.study.adapters import base_study_config, emulator_spec, new_posterior_shots, new_shot_config
from shockcal.study.config import prior_bounds
from shockcal.study.stages import stage_config
from shockcal.study.validate import load_config, validate_config

REPO = Path(__file__).resolve().parents[1]
QUICK = REPO / "config" / "quick.yaml"
SEQUENTIAL = REPO / "config" / "sequential-quick.yaml"


def with_shot(config: dict, name: str, velocity: str, increment: str, record: Path) -> dict:
    """`config` with a shot `name` on 106S's plates, its own impact velocity and modulus increment, and
    `record` (a copy of 106S's) as its record."""
    grown = copy.deepcopy(config)
    grown["inputs"][velocity] = dict(config["inputs"]["V3"])
    grown["inputs"][increment] = dict(config["inputs"]["Delta3"])
    grown["shots"][name] = dict(config["shots"]["106S"], velocity_input=velocity,
                                shear_modulus_inputs=["G1", increment])
    shutil.copy(REPO / config["observed"]["records"]["106S"]["path"], record)
    grown["observed"]["records"][name] = dict(config["observed"]["records"]["106S"], path=str(record))
    return validate_config(grown)


def test_adding_a_shot_changes_none_of_the_base_jobs_settings(paper_config, tmp_path):
    """What places a new shot's runs is computed under the study without it: every base job's config slice
    (the workflow's rerun trigger) is the three-shot study's, and a second new shot leaves the first's design
    settings alone, so adding a shot reruns no base run and no earlier new shot's."""
    three = validate_config(copy.deepcopy(paper_config))
    four = with_shot(three, "107S", "V4", "Delta4", tmp_path / "107S.txt")
    assert new_posterior_shots(three) == [] and new_posterior_shots(four) == ["107S"]
    for stage in ("merge_runs", "emulate", "calibrate", "wave_design", "observed"):
        assert stage_config(base_study_config(four), stage) == stage_config(three, stage), stage
    assert stage_config(four, "calibrate") != stage_config(three, "calibrate")      # the study's own calibrations do move
    five = with_shot(four, "108S", "V5", "Delta5", tmp_path / "108S.txt")
    assert (stage_config(new_shot_config(five, "107S"), "new_shot_design", "107S")
            == stage_config(new_shot_config(four, "107S"), "new_shot_design", "107S"))
    training = copy.deepcopy(four)
    training["design"]["new_shots"]["runs_from"] = "training"
    assert new_posterior_shots(validate_config(training)) == []


def test_a_new_shots_design_lies_in_the_posterior_with_its_own_inputs_stratified(paper_config):
    bounds = prior_bounds(paper_config)
    rng = np.random.default_rng(7)
    posterior = pd.DataFrame({k: lo + (hi - lo) * rng.uniform(0.45, 0.55, 3000) for k, (lo, hi) in bounds.items()})
    existing = posterior.iloc[:5].assign(run=np.arange(5))[["run", *bounds]]
    own = {"V4": (0.045, 0.052), "Delta4": (0.0, 0.2)}
    design = new_shot_design(posterior, bounds, own, 20, first_run=5, seed=3, own_seeds={"V4": 1, "Delta4": 2},
                             existing=existing, pool_size=1000)
    assert design.columns.tolist() == ["run", *bounds, *own] and design["run"].tolist() == list(range(5, 25))
    for name, (lo, hi) in bounds.items():
        assert ((design[name] - lo) / (hi - lo)).between(0.45, 0.55).all(), name
    for name, (lo, hi) in own.items():      # a Latin hypercube: one value in each twentieth of the box
        strata = np.floor((design[name] - lo) / (hi - lo) * 20).astype(int)
        assert sorted(strata) == list(range(20)), name
    again = new_shot_design(posterior, bounds, own, 20, 5, 3, {"V4": 1, "Delta4": 2}, existing, pool_size=1000)
    pd.testing.assert_frame_equal(design, again)


def test_a_new_shot_gets_an_emulator_block_of_its_own_on_its_own_runs(paper_config, tmp_path):
    """Joint structure: the base shots share one block on the design's rows; the new shot's block is fitted on
    its own design, whose run ids may repeat the others' (each block joins its features to its own rows)."""
    design, features, _ = _synthetic_study(paper_config, n=30)
    config = with_shot(paper_config, "107S", "V4", "Delta4", tmp_path / "107S.txt")
    config["emulator"].update(structure="joint", n_starts=1, cv_folds=3)
    own, own_features, _ = _synthetic_study(paper_config, n=20, seed=5)
    own = own.assign(V4=own["V3"], Delta4=own["Delta3"]).drop(columns=["V1", "V2", "V3", "Delta2", "Delta3"])
    spec = emulator_spec(config, ["104S", "105S", "106S", "107S"])
    spec = type(spec)(**{**spec.__dict__, "own_blocks": ("107S",)})
    emulator = fit_emulator(design, {"104S": features, "105S": features, "106S": features, "107S": own_features},
                            spec, shot_designs={"107S": own})
    assert [b.shots for b in emulator.blocks] == [["104S", "105S", "106S"], ["107S"]]
    assert sorted(emulator.blocks[1].runs) == sorted(own["run"]) and len(emulator.blocks[0].runs) == 30
    assert "V4" in emulator.blocks[1].input_map.design_inputs() and "V3" not in emulator.blocks[1].input_map.design_inputs()


def test_the_new_shot_design_command_refuses_a_base_shot_in_one_line(tmp_path, monkeypatch, capsys):
    """The command runs in this process (`python -m shockcal` costs seconds of imports), from the repository."""
    from shockcal.cli import main

    monkeypatch.chdir(REPO)
    code = main(["new-shot-design", "--config", "config/config.yaml", "--shot", "104S", "--posterior", "p.parquet",
                 "--runs", "r.parquet", "--out", str(tmp_path / "d.parquet")])
    stderr = capsys.readouterr().err
    assert code == 2 and len(stderr.strip().splitlines()) == 1, stderr
    assert "--shot: 104S is not a new shot" in stderr


def test_a_new_shot_with_one_run_is_refused_naming_the_key(paper_config):
    paper_config["design"]["new_shots"] = {"n_runs": 1}
    with pytest.raises(ConfigError, match=r"design\.new_shots\.n_runs: 1 is less than the minimum of 2"):
        validate_config(paper_config)


def shot_overlay(tmp_path: Path, results: Path, **design) -> Path:
    quick = load_config(REPO / "config" / "config.yaml")
    shot = dict(quick["shots"]["106S"], velocity_input="V4", shear_modulus_inputs=["G1", "Delta4"])
    return overlay(tmp_path / "shot.yaml", study={"results_dir": str(results)}, design=design,
                   inputs={"V4": quick["inputs"]["V3"], "Delta4": quick["inputs"]["Delta3"]},
                   shots={"107S": shot}, observed={"records": {"107S": _own_record(quick, tmp_path)}})


def test_a_new_shot_runs_only_its_own_rows_placed_by_the_base_shots_posterior(tmp_path):
    """A Latin-hypercube study: the base shots' emulator and joint posterior on the training runs (step 0) place
    the new shot's 20 runs; it runs no training row, and the study's emulator gets its design."""
    more = shot_overlay(tmp_path, tmp_path / "results")
    out = snakemake("all", "--dry-run", "--printshellcmds", config_files=[more]).stdout
    jobs = job_counts(out)
    assert jobs["simulate"] == 3 * 4                                    # the base shots' 40 training runs only
    assert jobs["simulate[new_shot]"] == 4 and jobs["features[new_shot]"] == 1     # 107S's 20 runs in 4 chunks
    assert jobs["new_shot_design"] == jobs["observed_base"] == 1
    assert jobs["merge_runs"] == jobs["wave_emulator"] == jobs["wave_calibrate"] == 1
    step = next(line for line in out.splitlines() if "shockcal calibrate" in line and "waves/step0" in line)
    assert "--shots 104S 105S 106S " in step
    study = next(line for line in out.splitlines() if "shockcal emulate" in line and "waves" not in line)
    assert f"--shot-design 107S={tmp_path}/results/new_shot/designs/107S.parquet" in study


def test_a_sequential_studys_waves_are_placed_for_the_base_shots_alone(tmp_path):
    """With a new shot the last step is computed too (it places the new shot's runs), and the waves run the
    base shots only."""
    results = tmp_path / "results"
    waves = overlay(tmp_path / "waves.yaml", study={"results_dir": str(results)})
    more = shot_overlay(tmp_path, results)
    jobs = pending_jobs(SEQUENTIAL, waves, more)
    assert jobs["simulate"] == 3 * 3 and jobs["simulate[wave1]"] == jobs["simulate[wave2]"] == 3
    assert jobs["wave_emulator"] == jobs["wave_calibrate"] == 3 and jobs["merge_runs"] == 3
    assert jobs["simulate[new_shot]"] == 4 and jobs["new_shot_design"] == 1


@pytest.mark.slow   # a sequential toy study with a new shot, to its joint posterior: about 4 min on 2 cores
def test_a_new_shot_in_a_sequential_study_end_to_end(tmp_path):
    """Waves placed for the base shots (their designs without the new shot's inputs), the last step placing the
    new shot's 20 runs, and the four-shot joint posterior from an emulator with the new shot's block."""
    results = tmp_path / "results"
    waves = overlay(tmp_path / "waves.yaml", study={"results_dir": str(results)})
    more = shot_overlay(tmp_path, results)
    done = snakemake(str(results / "posterior" / "joint.parquet"), "--cores", "2",
                     config_files=[SEQUENTIAL, waves, more], check=False)
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    for wave in (1, 2):
        design = pd.read_parquet(results / f"wave{wave}" / "design.parquet")
        assert len(design) == 10 and "V4" not in design.columns
    new = pd.read_parquet(results / "new_shot" / "designs" / "107S.parquet")
    runs = pd.read_parquet(results / "waves" / "step2" / "design.parquet")
    assert len(new) == 20 and new["run"].min() == runs["run"].max() + 1
    posterior = pd.read_parquet(results / "posterior" / "joint.parquet")
    assert {"V4", "Delta4", "V3"} <= set(posterior.columns)
    step = pd.read_parquet(results / "waves" / "step2" / "posterior" / "joint.parquet")
    assert "V4" not in step.columns
