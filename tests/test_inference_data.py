"""Posteriors as ArviZ InferenceData: `shockcal posterior-netcdf` writes a file ArviZ reads back with every
input in the units a user reads, lambda_y, the provenance and the groups (the README's ArviZ block runs on
the quick study: tests/test_study_results.py)."""

from __future__ import annotations

import subprocess
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from shockcal import __version__
from shockcal.cli import main
from shockcal.errors import InputError
from shockcal.inference.inference_data import config_digest, git_commit, observed_frames, posterior_inference_data
from shockcal.io import write_table
from shockcal.study.stages import load_stage_config
from shockcal.velocimetry.columns import CALIBRATION_FEATURES

az = pytest.importorskip("arviz")
REPO = Path(__file__).resolve().parents[1]
CONFIG = str(REPO / "config" / "config.yaml")
INPUTS_104S = ["A", "B", "C", "n", "m", "V1", "G1"]
# the inputs in the file: the unit a user reads in the name, and the factor from the config's Table IV unit
IN_FILE = {"A": ("A_MPa", 1e5), "B": ("B_MPa", 1e5), "C": ("C", 1.0), "n": ("n", 1.0), "m": ("m", 1.0),
           "V1": ("V1_m_s", 1e4), "G1": ("G1_GPa", 100.0)}
FILE_NAMES = [IN_FILE[k][0] for k in INPUTS_104S]


def write_posterior(tmp_path: Path, config: dict, shots=("104S",), inputs=INPUTS_104S, n=400) -> Path:
    """A posterior as `shockcal calibrate` writes it (draws, weighted draws, metadata), drawn in the box."""
    rng = np.random.default_rng(3)
    boxes = {k: (config["inputs"][k]["min"], config["inputs"][k]["max"]) for k in inputs}
    weighted = pd.DataFrame({k: rng.uniform(*boxes[k], 2 * n) for k in inputs})
    weighted["lambda_y"] = rng.gamma(5.0, 0.2, 2 * n)
    log_w = rng.normal(size=2 * n)
    weighted["log_weight"] = log_w - np.log(np.exp(log_w).sum())
    weighted["log_likelihood"] = rng.normal(-40, 2, 2 * n)
    draws = weighted.sample(n, weights=np.exp(weighted["log_weight"]), replace=True, random_state=1)
    draws = draws.drop(columns="log_weight").reset_index(drop=True)
    k = len(CALIBRATION_FEATURES)
    observed = list(rng.uniform(60, 400, k * len(shots)))
    meta = {"table": "posterior samples", "sampler": "nautilus", "n_live": 200, "n_eff_target": 400, "seed": 5,
            "log_evidence": -45.25, "log_evidence_sd": 0.04, "likelihood_evaluations": 6800, "cube_power": {"m": 2.0},
            "ess_kish": 430.0, "shots": list(shots), "parameters": list(inputs), "observed": observed,
            "observed_sd_m_s": [0.01 * v for v in observed],
            "units": {k: config["inputs"][k]["unit"] for k in inputs} | {"lambda_y": "-"}}
    path = tmp_path / "posterior" / "104S.parquet"
    path.parent.mkdir()
    write_table(draws, path, meta)
    write_table(weighted, path.with_name("104S_weighted.parquet"), meta)
    return path


@pytest.fixture(scope="module")
def netcdf(tmp_path_factory, paper_config_readonly):
    """A 104S posterior written by `shockcal posterior-netcdf` with two shots' posterior-predictive features."""
    tmp_path = tmp_path_factory.mktemp("netcdf")
    posterior = write_posterior(tmp_path, paper_config_readonly)
    predicted = pd.DataFrame({"run": [0, 1, 2], "status": ["ok", "failed", "ok"],
                              **{f: [100.0, np.nan, 120.0] for f in CALIBRATION_FEATURES}})
    write_table(predicted, tmp_path / "pred.parquet")
    out = tmp_path / "posterior" / "104S.nc"
    assert main(["posterior-netcdf", "--config", CONFIG, "--posterior", str(posterior), "--predicted-features",
                 f"104S={tmp_path / 'pred.parquet'}", "--out", str(out)]) == 0
    return out, posterior


def test_netcdf_reads_back_with_every_input_lambda_y_and_provenance(netcdf):
    out, posterior = netcdf
    idata = az.from_netcdf(out)
    draws = pd.read_parquet(posterior)
    assert set(idata.groups()) >= {"posterior", "sample_stats", "observed_data", "constant_data",
                                   "posterior_predictive", "weighted_posterior"}
    assert list(idata.posterior.data_vars) == [*FILE_NAMES, "lambda_y"]
    rows = idata.posterior["row"].to_numpy()
    for name, (file_name, factor) in [*IN_FILE.items(), ("lambda_y", ("lambda_y", 1.0))]:
        assert idata.posterior[file_name].shape == (1, len(draws))
        np.testing.assert_allclose(idata.posterior[file_name].to_numpy()[0], draws[name].to_numpy()[rows] * factor,
                                   rtol=1e-15)
    np.testing.assert_array_equal(idata.sample_stats["log_likelihood"].to_numpy()[0],
                                  draws["log_likelihood"].to_numpy()[rows])
    units = {name: idata.posterior[name].attrs["units"] for name in ("A_MPa", "G1_GPa", "V1_m_s", "C", "lambda_y")}
    assert units == {"A_MPa": "MPa", "G1_GPa": "GPa", "V1_m_s": "m/s", "C": "-", "lambda_y": "-"}
    for attrs in (idata.attrs, idata.posterior.attrs):
        assert attrs["shockcal_version"] == __version__
        assert attrs["log_evidence"] == -45.25 and attrs["log_evidence_sd"] == 0.04
        assert attrs["git_commit"] == git_commit() != ""
        assert attrs["config_digest"] == config_digest(load_stage_config(CONFIG, "calibrate"))
        assert attrs["n_live"] == 200 and attrs["cube_power"] == '{"m": 2.0}'
    box = idata.constant_data
    assert list(box["input"].to_numpy()) == FILE_NAMES and list(box["unit"].to_numpy()[[0, 5, 6]]) == ["MPa", "m/s", "GPa"]
    np.testing.assert_allclose(box["prior_lower"].sel(input="A_MPa"), 50.0)         # 0.0005 Mbar
    np.testing.assert_allclose(box["prior_upper"].sel(input="V1_m_s"), 216.0)       # 0.0216 cm/us
    assert np.all(box["prior_lower"] < box["prior_upper"])
    assert list(idata.observed_data.data_vars) == CALIBRATION_FEATURES
    np.testing.assert_allclose(box["v_elastic_sd"], 0.01 * idata.observed_data["v_elastic"])
    predictive = idata.posterior_predictive["v_plastic"].sel(shot="104S").to_numpy()[0]
    np.testing.assert_array_equal(predictive, [100.0, np.nan, 120.0])   # the failed run reads NaN
    weighted = idata["weighted_posterior"]
    assert np.isclose(np.exp(weighted["log_weight"]).sum(), 1.0) and "lambda_y" in weighted
    assert weighted["G1_GPa"].attrs["units"] == "GPa" and float(weighted["G1_GPa"].min()) >= 20.0   # 0.2 Mbar


def test_az_summary_works(netcdf):
    summary = az.summary(az.from_netcdf(netcdf[0]))
    assert list(summary.index) == [*FILE_NAMES, "lambda_y"]
    assert summary["mean"].notna().all() and (summary["sd"] > 0).all()


def test_git_commit_is_unknown_outside_a_checkout(tmp_path):
    assert git_commit(tmp_path) == "unknown"
    here = subprocess.run(["git", "-C", str(REPO), "rev-parse", "--short", "HEAD"], capture_output=True, text=True)
    if here.returncode == 0:
        assert git_commit() == here.stdout.strip()


def test_bad_inputs_are_one_line_errors(tmp_path, paper_config):
    draws = pd.DataFrame({"A": [0.002], "lambda_y": [1.0], "log_likelihood": [-3.0]})
    observed, sd = observed_frames(["104S"], [1.0, 2.0, 3.0, 4.0], [0.1] * 4)
    with pytest.raises(InputError, match="no prior box for inputs \\['A'\\]"):
        posterior_inference_data(draws, ["A", "lambda_y"], units={}, lower={}, upper={}, observed=observed,
                                 observed_sd=sd)
    with pytest.raises(InputError, match="columns \\['B'\\] missing"):
        posterior_inference_data(draws, ["A", "B", "lambda_y"], units={}, lower={"A": 0}, upper={"A": 1},
                                 observed=observed, observed_sd=sd)
    with pytest.raises(InputError, match="observed vector of 3 values"):
        observed_frames(["104S"], [1.0, 2.0, 3.0], [0.1] * 3)
    bare = tmp_path / "bare.parquet"
    write_table(draws, bare)
    assert main(["posterior-netcdf", "--config", CONFIG, "--posterior", str(bare), "--out", str(tmp_path / "x.nc")]) == 2
