"""The discrepancy's parameters in every door a user reads (issue 63): the posterior files and their summary,
the InferenceData (dimensionless, described, and the sd they imply in m/s), the report's tables; with
`calibration.discrepancy: none`, each of them as before."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from test_calibration import StandInEmulator

from shockcal.cli import main
from shockcal.errors import InputError
from shockcal.inference.calibration import calibrate
from shockcal.inference.discrepancy import enabled, implied_sd_table
from shockcal.inference.inference_data import observed_frames, posterior_inference_data
from shockcal.inference.posterior_files import companion_path, read_posterior, write_posterior
from shockcal.inference.sampler import Posterior, WeightedDraws
from shockcal.io import read_table_metadata
from shockcal.study.adapters import calibration_settings
from shockcal.velocimetry.columns import CALIBRATION_FEATURES

az = pytest.importorskip("arviz")
REPO = Path(__file__).resolve().parents[1]
FEATURES = CALIBRATION_FEATURES          # v_elastic, v_plastic, v_slope1, v_slope2
OBSERVED = pd.DataFrame([{"shot": "S1", "v_elastic": 118.0, "v_plastic": 87.2, "v_slope1": 120.0, "v_slope2": 86.0},
                         {"shot": "S2", "v_elastic": 121.0, "v_plastic": 88.0, "v_slope1": 122.0, "v_slope2": 87.0}])
DELTA = [f"delta_sd_fraction_{f}" for f in FEATURES] + ["delta_rho_shots"]


def _mean(theta):
    a = theta[:, 0] ** 2
    return np.column_stack([100 + 50 * a, 80 + 20 * a, 103 + 50 * a, 79 + 20 * a] * 2)


def prior_importance_sample(problem, settings, other_powers="error"):
    """A stand-in for nautilus: 4000 prior draws weighted by their likelihood (a valid, if crude, posterior
    estimate; the sampler itself is tested in test_calibration), then equal-weight draws as `sample` makes them."""
    from scipy.special import logsumexp

    points = problem.prior_transform(np.random.default_rng(settings.seed).uniform(size=(4000, problem.ndim)))
    log_l = problem.log_likelihood(points)
    weighted = WeightedDraws(points, log_l - logsumexp(log_l), log_l, float(logsumexp(log_l) - np.log(4000)), 4000)
    names = [*problem.names, "lambda_y", *problem.discrepancy_names]
    rows = weighted.resample(settings.draws, np.random.default_rng(settings.seed))
    draws = pd.DataFrame(points[rows], columns=names).assign(log_likelihood=log_l[rows])
    return Posterior(names, weighted, draws, settings, {}, int(len(np.unique(rows))))


@pytest.fixture(scope="module")
def posteriors(paper_config_readonly):
    """Two shots calibrated with the discrepancy and without it (prior importance sampling for nautilus)."""
    import copy

    config = copy.deepcopy(paper_config_readonly)
    config["inputs"]["A"] = {"min": -1, "max": 1, "unit": "Mbar"}
    config["calibration"].update(draws=600)
    emulator = StandInEmulator(_mean, ["A"], [-1], [1], 0.01 * np.eye(8))
    emulator.feature_names = FEATURES
    runs = {}
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr("shockcal.inference.calibration.sample", prior_importance_sample)
        for name, setting in (("none", "none"), ("with", {"kind": "feature_kind", "sd_fraction_prior": 0.02})):
            config["calibration"]["discrepancy"] = setting
            runs[name] = calibrate(emulator, ["S1", "S2"], OBSERVED, calibration_settings(config, ["S1", "S2"]))
    return runs


def _inference_data(posterior):
    info = posterior.info()
    observed, sd = observed_frames(info["shots"], info["observed"], info["observed_sd_m_s"], FEATURES)
    return posterior_inference_data(posterior.draws, posterior.names, units=posterior.units,
                                    user_units=posterior.user_units, lower={"A": -1.0}, upper={"A": 1.0},
                                    observed=observed, observed_sd=sd, weighted=posterior.weighted_table())


def test_summary_and_files_carry_the_discrepancy_dimensionless(posteriors, tmp_path):
    posterior = posteriors["with"]
    summary = posterior.summary().set_index("parameter")
    assert list(summary.index) == ["A_MPa", "lambda_y", *DELTA]
    assert (summary.loc[DELTA, "unit"] == "-").all()
    assert summary.loc["delta_rho_shots", "q05"] >= 0 and summary.loc["delta_rho_shots", "q95"] <= 1
    assert (summary.loc[DELTA[:2], "q05"] >= 0).all()
    out = tmp_path / "joint.parquet"
    info = write_posterior(posterior, out)
    assert info["discrepancy_parameters"] == DELTA and info["discrepancy_sd_fraction_prior"] == 0.02
    back = read_posterior(out)
    assert back.names == posterior.names
    pd.testing.assert_frame_equal(back.draws, posterior.draws)
    pd.testing.assert_frame_equal(back.summary(), posterior.summary())


def test_without_a_discrepancy_the_posterior_files_are_as_before(posteriors, tmp_path):
    posterior = posteriors["none"]
    assert posterior.names == ["A", "lambda_y"] and list(posterior.draws.columns) == ["A", "lambda_y", "log_likelihood"]
    info = write_posterior(posterior, tmp_path / "joint.parquet")
    assert not any("discrepancy" in key for key in info)
    assert not any("discrepancy" in key for key in read_table_metadata(tmp_path / "joint.parquet"))
    assert list(posterior.summary()["parameter"]) == ["A_MPa", "lambda_y"]
    assert read_posterior(tmp_path / "joint.parquet").names == ["A", "lambda_y"]
    assert not enabled("none") and not enabled(None) and not enabled({"kind": "none"})
    assert enabled({"kind": "feature_kind", "sd_fraction_prior": 0.02})


def test_inference_data_names_describes_and_scales_the_discrepancy(posteriors):
    posterior = posteriors["with"]
    idata = _inference_data(posterior)
    group = idata.posterior
    for name in DELTA:
        assert group[name].attrs["units"] == "-" and "model discrepancy" in group[name].attrs["description"]
        assert name in idata["weighted_posterior"]
    assert list(idata.constant_data["input"].to_numpy()) == ["A_MPa"]     # no prior box for the discrepancy
    rows = group["row"].to_numpy()
    for feature in FEATURES:
        implied = group[f"delta_sd_{feature}_m_s"]
        assert implied.dims == ("chain", "draw", "shot") and implied.attrs["units"] == "m/s"
        fraction = posterior.draws[f"delta_sd_fraction_{feature}"].to_numpy()[rows]
        np.testing.assert_allclose(implied.sel(shot="S2").to_numpy()[0], fraction * OBSERVED.loc[1, feature],
                                   rtol=1e-15)
    summary = az.summary(idata)
    assert "delta_sd_v_plastic_m_s[S1]" in summary.index and summary.loc["delta_rho_shots", "mean"] > 0


def test_posterior_netcdf_writes_the_discrepancy_from_calibrate_s_files(posteriors, tmp_path):
    write_posterior(posteriors["with"], tmp_path / "joint.parquet")
    out = tmp_path / "joint.nc"
    assert main(["posterior-netcdf", "--config", str(REPO / "config" / "config.yaml"), "--posterior", str(tmp_path / "joint.parquet"),
                 "--out", str(out)]) == 0
    idata = az.from_netcdf(out)
    assert [name for name in idata.posterior.data_vars if name.startswith("delta_")] == [
        *DELTA, *(f"delta_sd_{f}_m_s" for f in FEATURES)]
    assert idata.posterior.attrs["discrepancy_sd_fraction_prior"] == 0.02


def test_inference_data_without_a_discrepancy_is_as_before(posteriors):
    idata = _inference_data(posteriors["none"])
    assert list(idata.posterior.data_vars) == ["A_MPa", "lambda_y"]
    assert "shot" not in idata.posterior.coords
    assert all(set(var.attrs) == {"units"} for var in idata.posterior.data_vars.values())
    assert list(idata["weighted_posterior"].data_vars) == ["A_MPa", "lambda_y", "log_weight", "log_likelihood"]


def test_implied_sd_is_the_fraction_times_the_measured_feature(posteriors):
    posterior = posteriors["with"]
    observed, _ = observed_frames(["S1", "S2"], posterior.info()["observed"], posterior.info()["observed_sd_m_s"],
                                  FEATURES)
    table = implied_sd_table(posterior.summary(), observed)
    assert list(zip(table["shot"], table["feature"])) == [("S1", f) for f in FEATURES] + [("S2", f) for f in FEATURES]
    summary = posterior.summary().set_index("parameter")
    row = table.iloc[5]            # S2, v_plastic: 88.0 m/s
    assert row["observed_m_s"] == 88.0
    for q in ("q05", "q50", "q95"):
        assert row[f"fraction_{q}"] == summary.loc["delta_sd_fraction_v_plastic", q]
        assert row[f"sd_m_s_{q}"] == pytest.approx(88.0 * summary.loc["delta_sd_fraction_v_plastic", q], rel=1e-15)
    assert implied_sd_table(posteriors["none"].summary(), observed).empty


def test_calibrate_logs_the_implied_sd_in_m_s(posteriors, caplog):
    from shockcal.cli.calibrate import log_discrepancy

    with caplog.at_level("INFO", logger="shockcal.calibrate"):
        log_discrepancy(posteriors["with"], FEATURES)
    assert "model discrepancy's sd (m/s)" in caplog.text and "sd_m_s_q50" in caplog.text and "S2" in caplog.text


def test_report_tables_write_the_discrepancy_table_and_refuse_a_posterior_without_one(posteriors, tmp_path, capsys):
    write_posterior(posteriors["with"], tmp_path / "with.parquet")
    write_posterior(posteriors["none"], tmp_path / "none.parquet")
    assert companion_path(tmp_path / "with.parquet").is_file()
    out = tmp_path / "report"
    assert main(["report-tables", "--discrepancy", f"joint={tmp_path / 'with.parquet'}", "--out-dir", str(out)]) == 0
    table = pd.read_csv(out / "discrepancy.csv")
    assert list(table["calibration"].unique()) == ["joint"] and len(table) == 8
    assert "sd_m_s_q50" in table and "<table" in (out / "discrepancy.html").read_text()
    capsys.readouterr()
    assert main(["report-tables", "--discrepancy", f"joint={tmp_path / 'none.parquet'}", "--out-dir", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert "a posterior without a model discrepancy" in err and len(err.splitlines()) == 1
    with pytest.raises(InputError, match="go together"):
        from argparse import Namespace

        from shockcal.cli.report import predictive_table
        predictive_table(Namespace(predictive_posterior="x", predictive_design=None, predictive_emulator=None))
