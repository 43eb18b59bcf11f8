"""Design tables: the seeded Latin hypercube, user designs and the per-shot mapping."""

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from shockcal.cli import main
from shockcal.design.tables import chunk_fingerprints, latin_hypercube
from shockcal.errors import InputError
from shockcal.io import read_table
from shockcal.study.adapters import input_box, load_study_design, shot_mapping
from shockcal.study.config import prior_bounds
from shockcal.study.validate import load_config

REPO = Path(__file__).resolve().parents[1]


def test_latin_hypercube_fills_the_box_one_point_per_stratum(paper_config):
    design = latin_hypercube(prior_bounds(paper_config), 50, seed=3)
    assert list(design["run"]) == list(range(50))
    for name, box in paper_config["inputs"].items():
        strata = np.floor((design[name] - box["min"]) / (box["max"] - box["min"]) * 50).astype(int)
        assert sorted(strata) == list(range(50)), name


def test_latin_hypercube_is_reproducible_and_seed_dependent(paper_config):
    a = latin_hypercube(prior_bounds(paper_config), 20, seed=7)
    pd.testing.assert_frame_equal(a, latin_hypercube(prior_bounds(paper_config), 20, seed=7))
    assert not a.equals(latin_hypercube(prior_bounds(paper_config), 20, seed=8))


def test_shot_mapping_sums_shear_modulus_terms(paper_config):
    row = {"A": 0.002, "B": 0.004, "C": 0.01, "n": 0.5, "m": 1.0, "V1": 0.0204, "V2": 0.0355,
           "V3": 0.0484, "G1": 0.27, "Delta2": 0.01, "Delta3": 0.02}
    p104 = shot_mapping(paper_config, "104S").parameters(row)
    p106 = shot_mapping(paper_config, "106S").parameters(row)
    assert p104.table_iv().velocity_cm_us == 0.0204 and p104.table_iv().shear_modulus_Mbar == pytest.approx(0.27)
    assert p106.table_iv().velocity_cm_us == 0.0484 and p106.table_iv().shear_modulus_Mbar == pytest.approx(0.30)


def test_load_design_reads_csv_and_adds_run(tmp_path, paper_config):
    design = latin_hypercube(prior_bounds(paper_config), 5, seed=1).drop(columns="run")
    path = tmp_path / "d.csv"
    design.to_csv(path, index=False)
    loaded = load_study_design(path, paper_config)
    assert list(loaded["run"]) == [0, 1, 2, 3, 4]
    np.testing.assert_allclose(loaded["A"], design["A"])


@pytest.mark.parametrize("mutate, message", [
    (lambda d: d.drop(columns="Delta3"), "missing column"),
    (lambda d: d.assign(n=[0.1, -0.2, 0.3]), "run 1: parameter n"),
    (lambda d: d.assign(A=[0.001, np.nan, 0.001]), "run 1: parameter A is not a finite number"),
    (lambda d: d.assign(run=[4, 4, 5]), "run id 4 appears more than once"),
])
def test_load_design_rejects_bad_tables_naming_row_and_parameter(tmp_path, paper_config, mutate, message):
    path = tmp_path / "bad.csv"
    mutate(latin_hypercube(prior_bounds(paper_config), 3, seed=1)).to_csv(path, index=False)
    with pytest.raises(InputError, match=message) as err:
        load_study_design(path, paper_config)
    assert "bad.csv" in str(err.value)


def test_non_positive_shot_velocity_is_rejected_before_running(paper_config):
    design = latin_hypercube(prior_bounds(paper_config), 3, seed=1)
    design.loc[2, "V2"] = 0.0
    shot_mapping(paper_config, "104S").check_positive(design, "d.csv")  # 104S does not use V2
    with pytest.raises(InputError, match="run 2: impact velocity V2"):
        shot_mapping(paper_config, "105S").check_positive(design, "d.csv")


def test_design_depends_on_inputs_and_seed_not_on_their_order(paper_config):
    # the workflow's jobs read a key-sorted copy of the config; the Snakefile plans chunks on the
    # config as written: both must see the same design (and the same chunk digests)
    shuffled = {**paper_config, "inputs": dict(sorted(paper_config["inputs"].items()))}
    a = latin_hypercube(prior_bounds(paper_config), 30, seed=4)
    b = latin_hypercube(prior_bounds(shuffled), 30, seed=4)
    assert list(a.columns) == ["run", *paper_config["inputs"]]
    pd.testing.assert_frame_equal(a, b[a.columns])
    assert chunk_fingerprints(a, 10) == chunk_fingerprints(b, 10)


def test_write_design_rewrites_only_changed_rows(paper_config, tmp_path):
    """The workflow writes the design every time it is read: the same rows leave the file (and its
    mtime, which the emulator's rerun follows) alone, from any source; other rows replace it."""
    from shockcal.design.tables import write_design

    design, path = latin_hypercube(prior_bounds(paper_config), 6, seed=1), tmp_path / "design.parquet"
    assert write_design(design, "Latin hypercube, seed 1", input_box(paper_config), path)
    assert not write_design(design.copy(), "file saved.csv", input_box(paper_config), path)
    grown = pd.concat([design, latin_hypercube(prior_bounds(paper_config), 1, seed=2).assign(run=6)], ignore_index=True)
    assert write_design(grown, "file saved.csv", input_box(paper_config), path)
    assert pd.read_parquet(path).equals(grown[["run", *design.columns[1:]]])


def _with_fourth_shot(config, base_shots):
    """The study with a shot 107S that brings its own impact velocity V4 and modulus increment Delta4."""
    config["design"]["base_shots"] = base_shots
    config["inputs"]["V4"] = dict(config["inputs"]["V3"])
    config["inputs"]["Delta4"] = dict(config["inputs"]["Delta3"])
    config["shots"]["107S"] = dict(config["shots"]["106S"], velocity_input="V4",
                                   shear_modulus_inputs=["G1", "Delta2", "Delta4"])
    return config


def test_the_study_design_is_the_hypercube_over_the_base_shots_inputs(paper_config):
    from shockcal.study.adapters import study_design

    design, _ = study_design(paper_config, n_runs=40)
    pd.testing.assert_frame_equal(design, latin_hypercube(prior_bounds(paper_config), 40, paper_config["study"]["seed"]))


def test_an_added_shot_draws_its_own_inputs_and_leaves_every_column_alone(paper_config):
    from shockcal.study.adapters import study_design

    before, _ = study_design(paper_config, n_runs=40)
    after, source = study_design(_with_fourth_shot(paper_config, ["104S", "105S", "106S"]), n_runs=40)
    pd.testing.assert_frame_equal(after[before.columns], before)
    assert list(after.columns) == [*before.columns, "V4", "Delta4"] and "drawn for shot(s) 107S" in source
    for name in ("V4", "Delta4"):                       # a one-dimensional Latin hypercube: one point per stratum
        box = paper_config["inputs"][name]
        strata = np.floor((after[name] - box["min"]) / (box["max"] - box["min"]) * 40).astype(int)
        assert sorted(strata) == list(range(40)), name
    assert abs(np.corrcoef(after["V4"], after["Delta4"])[0, 1]) < 0.5          # own seeds: not the same permutation
    again, _ = study_design(paper_config, n_runs=40)
    pd.testing.assert_frame_equal(again, after)                                   # seeded by the shot and input


def test_a_design_file_keeps_its_columns_and_gets_the_added_shots_missing_ones(paper_config, tmp_path):
    from shockcal.study.adapters import study_design

    base = latin_hypercube(prior_bounds(paper_config), 12, seed=5)
    config = _with_fourth_shot(paper_config, ["104S", "105S", "106S"])
    base.to_csv(tmp_path / "d.csv", index=False)
    config["design"]["file"] = str(tmp_path / "d.csv")
    drawn, _ = study_design(config)
    pd.testing.assert_frame_equal(drawn[base.columns], base)
    base.assign(V4=0.05, Delta4=0.1).to_csv(tmp_path / "d.csv", index=False)
    given, _ = study_design(config)
    assert (given["V4"] == 0.05).all() and (given["Delta4"] == 0.1).all()


def test_base_shots_must_name_shots(paper_config):
    from shockcal.errors import ConfigError
    from shockcal.study.validate import validate_config

    paper_config["design"]["base_shots"] = ["104S", "108S"]
    with pytest.raises(ConfigError, match=r"design\.base_shots: '108S' is not a shot"):
        validate_config(paper_config)


@pytest.mark.parametrize("stream", ["design", "check_design"])
def test_the_design_commands_read_only_their_stages_keys(tmp_path, stream):
    """`shockcal design` as the rules design and check_design run it, on the default study: each reads
    its stage's slice of the config only (a key outside it is a KeyError), the check's design a
    hypercube of calibration.check.trials runs over every input, its modulus increments included."""
    config = load_config(REPO / "config" / "config.yaml")
    out = tmp_path / "design.parquet"
    assert main(["design", "--config", str(REPO / "config" / "config.yaml"), "--stream", stream, "--out", str(out)]) == 0
    design = read_table(out)
    rows = config["calibration"]["check"]["trials"] if stream == "check_design" else config["design"]["n_runs"]
    assert len(design) == rows and list(design.columns) == ["run", *config["inputs"]]
