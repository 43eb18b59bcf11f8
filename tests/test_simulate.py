"""Batch runs: the simulations table, failures recorded not raised, bad input caught before running."""

import numpy as np
import pandas as pd
import pytest
import yaml

from shockcal import hydro
from shockcal.cli import main
from shockcal.design.tables import latin_hypercube
from shockcal.simulators.builtin import simulate_design
from shockcal.study.adapters import hydro_inputs, shot_mapping
from shockcal.study.config import prior_bounds


@pytest.fixture
def coarse_config(paper_config, tmp_path):
    paper_config["hydro"].update(cell_size_um=20.0, end_time_us=1.5)
    path = tmp_path / "config.yaml"
    path.write_text(yaml.safe_dump(paper_config))
    return paper_config, path


def test_table_has_documented_columns(coarse_config):
    config, _ = coarse_config
    design = latin_hypercube(prior_bounds(config), 2, seed=1)
    table = simulate_design(design, shot_mapping(config, "105S"), *hydro_inputs(config, config["shots"]["105S"]))
    expected = {"run", "shot", "A", "B", "C", "n", "m", "V2", "G1", "Delta2", "impact_velocity_m_s", "shear_modulus_GPa",
                "status", "reason", "max_strain_rate_per_us", "max_temperature_K", "max_plastic_strain", "energy_error",
                "n_steps", "wall_time_s", "t_us", "v_m_s"}
    assert set(table.columns) == expected
    assert list(table["status"]) == ["ok", "ok"]
    assert table["shear_modulus_GPa"].iloc[0] == pytest.approx(100 * (design["G1"] + design["Delta2"]).iloc[0])
    assert len(table["t_us"].iloc[0]) == len(table["v_m_s"].iloc[0]) == 3001


def test_a_failing_run_is_recorded_and_the_batch_goes_on(coarse_config, monkeypatch):
    config, _ = coarse_config
    real = hydro.run_shot

    def flaky(params, *inputs):
        if params.table_iv().A_Mbar == design["A"].iloc[1]:
            raise FloatingPointError("synthetic failure")
        return real(params, *inputs)

    design = latin_hypercube(prior_bounds(config), 3, seed=2)
    monkeypatch.setattr("shockcal.simulators.builtin.run_shot", flaky)
    table = simulate_design(design, shot_mapping(config, "104S"), *hydro_inputs(config, config["shots"]["104S"]))
    assert list(table["status"]) == ["ok", "failed", "ok"]
    assert "synthetic failure" in table["reason"].iloc[1]
    assert np.isnan(table["max_temperature_K"].iloc[1])


def test_cli_writes_the_slice_and_is_deterministic(coarse_config, tmp_path):
    config, path = coarse_config
    latin_hypercube(prior_bounds(config), 4, seed=3).to_csv(tmp_path / "d.csv", index=False)
    for name in ("a", "b"):
        assert main(["simulate", "--config", str(path), "--shot", "106S", "--design", str(tmp_path / "d.csv"),
                     "--rows", "1:3", "--out", str(tmp_path / f"{name}.parquet")]) == 0
    a, b = (pd.read_parquet(tmp_path / f"{n}.parquet") for n in "ab")
    assert list(a["run"]) == [1, 2]
    for col in ("v_m_s",):
        assert all(np.array_equal(x, y) for x, y in zip(a[col], b[col]))


def test_bad_design_is_rejected_before_any_run(coarse_config, tmp_path, capsys):
    config, path = coarse_config
    design = latin_hypercube(prior_bounds(config), 3, seed=4)
    design.loc[2, "n"] = -0.1
    design.to_csv(tmp_path / "bad.csv", index=False)
    assert main(["simulate", "--config", str(path), "--shot", "104S", "--design", str(tmp_path / "bad.csv"),
                 "--out", str(tmp_path / "o.parquet")]) == 2
    assert "bad.csv: run 2: parameter n" in capsys.readouterr().err
    assert not (tmp_path / "o.parquet").exists()
    assert main(["simulate", "--config", str(path), "--shot", "107S", "--design", str(tmp_path / "bad.csv"),
                 "--out", str(tmp_path / "o.parquet")]) == 2
    assert "unknown shot '107S'" in capsys.readouterr().err
