"""Posterior draws for hydrocode runs: seeded, shaped like a design, clear errors on bad posteriors."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from shockcal.cli import main
from shockcal.design.posterior_draws import draw_posterior_design
from shockcal.errors import InputError
from shockcal.io import read_table, write_table
from shockcal.study.config import input_names

CONFIG = str(Path(__file__).resolve().parents[1] / "config" / "config.yaml")


def _posterior(config, n):
    rng = np.random.default_rng(1)
    names = input_names(config)
    lo = np.array([config["inputs"][k]["min"] for k in names])
    hi = np.array([config["inputs"][k]["max"] for k in names])
    table = pd.DataFrame(lo + rng.random((n, len(names))) * (hi - lo), columns=names)
    return table.assign(lambda_y=rng.gamma(5.0, 0.2, n), log_post=0.0, chain=rng.integers(0, 4, n))


def test_draws_are_posterior_rows_shaped_like_a_design(paper_config):
    post = _posterior(paper_config, 500)
    design = draw_posterior_design(post, input_names(paper_config), 100, seed=3)
    assert list(design.columns) == ["run", *input_names(paper_config)]
    assert design["run"].tolist() == list(range(100))
    assert len(design.merge(post, on=input_names(paper_config))) == 100  # every row is a posterior sample
    assert not design.duplicated(input_names(paper_config)).any()
    pd.testing.assert_frame_equal(design, draw_posterior_design(post, input_names(paper_config), 100, seed=3))
    assert not design.equals(draw_posterior_design(post, input_names(paper_config), 100, seed=4))


def test_small_posterior_is_drawn_with_replacement(paper_config):
    assert len(draw_posterior_design(_posterior(paper_config, 10), input_names(paper_config), 30, seed=0)) == 30


def test_empty_or_single_shot_posterior_is_refused(paper_config):
    with pytest.raises(InputError, match="post.parquet: posterior has no samples"):
        draw_posterior_design(_posterior(paper_config, 0), input_names(paper_config), 5, 0, source="post.parquet")
    with pytest.raises(InputError, match="missing column.*V2"):
        draw_posterior_design(_posterior(paper_config, 50).drop(columns=["V2"]), input_names(paper_config), 5, 0)


def test_cli_writes_the_design(paper_config, tmp_path, capsys):
    posterior = tmp_path / "joint.parquet"
    write_table(_posterior(paper_config, 200), posterior)
    out = tmp_path / "design.parquet"
    assert main(["predict", "--config", CONFIG, "--posterior", str(posterior), "--out", str(out),
                 "--n-runs", "20"]) == 0
    design = read_table(out)
    assert len(design) == 20 and list(design.columns) == ["run", *input_names(paper_config), "lambda_y"]
    drawn = design.merge(_posterior(paper_config, 200), on=input_names(paper_config), suffixes=("", "_posterior"))
    assert len(drawn) == 20 and (drawn["lambda_y"] == drawn["lambda_y_posterior"]).all()   # each draw's own
    other = tmp_path / "check.parquet"
    assert main(["predict", "--config", CONFIG, "--posterior", str(posterior), "--out", str(other),
                 "--n-runs", "20", "--stream", "check_posterior"]) == 0
    assert not read_table(other).equals(design)                 # the check's truths: a stream of their own
    for stream, n_draws in [("check_posterior", paper_config["calibration"]["check"]["trials"]),
                            ("verify", paper_config["verify"]["n_draws"])]:   # each stream's own count, from its slice
        assert main(["predict", "--config", CONFIG, "--posterior", str(posterior), "--out", str(other),
                     "--stream", stream]) == 0
        assert len(read_table(other)) == n_draws
    assert main(["predict", "--config", CONFIG, "--posterior", str(tmp_path / "nope.parquet"),
                 "--out", str(out)]) == 2
    assert "nope.parquet does not exist" in capsys.readouterr().err
    assert main(["predict", "--config", CONFIG, "--posterior", str(posterior), "--out", str(out),
                 "--stream", "nope"]) == 2
    assert "--stream: 'nope' is not a stream of posterior draws (posterior_draws, check_posterior, verify)" in \
        capsys.readouterr().err


def test_cli_carries_the_discrepancy_s_columns_after_lambda_y(paper_config, tmp_path):
    """A posterior with a discrepancy (its parameters in the draws) gives a design that carries them, for the
    predictive coverage with and without it; the inputs and lambda_y are drawn as without one."""
    posterior = tmp_path / "joint.parquet"
    delta = ["delta_sd_fraction_v_elastic", "delta_sd_fraction_v_plastic", "delta_sd_fraction_v_slope1",
             "delta_sd_fraction_v_slope2", "delta_rho_shots"]
    table = _posterior(paper_config, 200)
    write_table(table.assign(**{name: np.linspace(0.0, 0.05, 200) + k for k, name in enumerate(delta)}), posterior)
    out, plain = tmp_path / "design.parquet", tmp_path / "plain.parquet"
    assert main(["predict", "--config", CONFIG, "--posterior", str(posterior), "--out", str(out), "--n-runs", "20"]) == 0
    design = read_table(out)
    assert list(design.columns) == ["run", *input_names(paper_config), "lambda_y", *delta]
    write_table(table, tmp_path / "none.parquet")
    assert main(["predict", "--config", CONFIG, "--posterior", str(tmp_path / "none.parquet"), "--out", str(plain),
                 "--n-runs", "20"]) == 0
    pd.testing.assert_frame_equal(design.drop(columns=delta), read_table(plain))


class _LinearEmulator:
    """Stands in for shockcal.emulator.study_emulator.Emulator: features = 1e4 * V of the shot, sd 2 m/s."""

    feature_names = ["v_elastic", "v_plastic", "v_slope1", "v_slope2"]
    velocity = {"104S": "V1", "105S": "V2"}

    def predict(self, inputs, shots):
        mean = np.column_stack([1e4 * inputs[self.velocity[s]] + k for s in shots for k in range(4)])
        cov = np.broadcast_to(4.0 * np.eye(mean.shape[1]), (len(mean), mean.shape[1], mean.shape[1]))
        return mean, cov


def test_emulator_predictions_one_row_per_run_and_shot(paper_config):
    from shockcal.inference.predict import emulator_predictions

    design = draw_posterior_design(_posterior(paper_config, 50), input_names(paper_config), 10, seed=0)
    table = emulator_predictions(_LinearEmulator(), design, ["104S", "105S"])
    assert len(table) == 20 and set(table["shot"]) == {"104S", "105S"}
    row = table[(table["shot"] == "105S") & (table["run"] == 3)].iloc[0]
    assert row["v_plastic"] == pytest.approx(1e4 * design.loc[3, "V2"] + 1)
    assert row["v_slope2_sd"] == pytest.approx(2.0)
