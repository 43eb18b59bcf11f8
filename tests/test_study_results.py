"""A finished study read back as a user reads it: the InferenceData in MPa, GPa and m/s (az.summary
like the paper's Table V), `shockcal.load_study` with its posteriors, emulator and measured features,
and the README's ArviZ block as written. All on the session's quick study (tests/conftest.py)."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import shockcal
from shockcal.errors import InputError
from shockcal.inference.posterior_files import read_posterior
from shockcal.io import read_table_metadata

az = pytest.importorskip("arviz")
REPO = Path(__file__).resolve().parents[1]
# quick.yaml's box in user units: A, B 50-1000 MPa, G1 20-50 GPa, Delta2 0-10 GPa, Delta3 0-20 GPa, V in m/s
USER_BOX = {"A_MPa": (50, 1000), "B_MPa": (50, 1000), "C": (0, 0.03), "n": (0, 1.5), "m": (0, 3),
            "V1_m_s": (192, 216), "V2_m_s": (334, 376), "V3_m_s": (455, 513), "G1_GPa": (20, 50),
            "Delta2_GPa": (0, 10), "Delta3_GPa": (0, 20)}


def test_az_summary_of_the_joint_netcdf_reads_in_mpa_gpa_and_m_s(quick_study):
    results, _ = quick_study
    idata = az.from_netcdf(results / "posterior" / "joint.nc")
    summary = az.summary(idata)                    # rounds to 3 decimals, as a user sees it
    assert sorted(summary.index) == sorted([*USER_BOX, "lambda_y"])
    for name, (low, high) in USER_BOX.items():
        assert low <= summary.loc[name, "mean"] <= high, (name, summary.loc[name])
        assert summary.loc[name, "sd"] > 0, name   # 0.000 in Mbar or cm/us at 3 decimals
    assert summary.loc["A_MPa", "mean"] > 100 and summary.loc["V1_m_s", "sd"] >= 0.5
    units = {name: idata.posterior[name].attrs["units"] for name in USER_BOX}
    assert units == {"A_MPa": "MPa", "B_MPa": "MPa", "C": "-", "n": "-", "m": "-", "V1_m_s": "m/s", "V2_m_s": "m/s",
                     "V3_m_s": "m/s", "G1_GPa": "GPa", "Delta2_GPa": "GPa", "Delta3_GPa": "GPa"}
    draws = pd.read_parquet(results / "posterior" / "joint.parquet")     # the draws in the design's Mbar, cm/us
    rows = idata.posterior["row"].to_numpy()
    np.testing.assert_allclose(idata.posterior["A_MPa"].to_numpy()[0], 1e5 * draws["A"].to_numpy()[rows], rtol=1e-15)
    np.testing.assert_allclose(idata.posterior["V2_m_s"].to_numpy()[0], 1e4 * draws["V2"].to_numpy()[rows], rtol=1e-15)
    box = idata.constant_data
    np.testing.assert_allclose(box["prior_lower"].sel(input="G1_GPa"), 20.0, rtol=1e-12)
    np.testing.assert_allclose(box["prior_upper"].sel(input="A_MPa"), 1000.0, rtol=1e-12)


def test_summary_table_is_in_user_units_and_load_study_recomputes_it(quick_study):
    results, _ = quick_study
    written = pd.read_parquet(results / "posterior" / "104S_summary.parquet")
    units = dict(zip(written["parameter"], written["unit"]))
    assert units == {"A_MPa": "MPa", "B_MPa": "MPa", "C": "-", "n": "-", "m": "-", "V1_m_s": "m/s", "G1_GPa": "GPa",
                     "lambda_y": "-"}
    posterior = read_posterior(results / "posterior" / "104S.parquet")
    pd.testing.assert_frame_equal(posterior.summary(), written)        # the same weighted draws, the same code
    native = posterior.summary(native=True).set_index("parameter")
    np.testing.assert_allclose(written.set_index("parameter").loc["G1_GPa", ["mean", "q05", "q95"]].to_numpy(float),
                               100 * native.loc["G1", ["mean", "q05", "q95"]].to_numpy(float), rtol=1e-12)


def test_load_study_holds_posteriors_inference_data_emulator_and_features(quick_study):
    results, _ = quick_study
    study = shockcal.load_study(results)
    assert study.shots == ["104S", "105S", "106S"]
    assert list(study.posteriors) == list(study.inference_data) == ["104S", "105S", "106S", "joint"]
    joint = study.posteriors["joint"]
    assert joint.log_evidence == study.inference_data["joint"].attrs["log_evidence"]
    assert len(joint.draws) == study.inference_data["joint"].posterior.sizes["draw"]
    assert "posterior_predictive" in study.inference_data["joint"].groups()
    assert study.emulator.shots == study.shots and sorted(study.observed["shot"]) == study.shots
    predicted, _ = study.emulator.predict(joint.draws.head(5), study.shots)   # the emulator works on the draws
    assert predicted.shape == (5, 12) and np.all(np.isfinite(predicted))
    text = repr(study)
    assert str(results) in text and "104S, 105S, 106S" in text and "log Z" in text
    assert f"{joint.log_evidence:.3f}" in text and f"{len(joint.draws):>6}" in text
    assert "load_study" in dir(shockcal)


def test_load_study_refuses_what_is_not_a_finished_study_in_one_line(quick_study, tmp_path):
    results, _ = quick_study
    with pytest.raises(InputError, match="no such directory"):
        shockcal.load_study(tmp_path / "nowhere")
    with pytest.raises(InputError, match=r"not a finished study \(posterior/joint.parquet, emulator/emulator.json"):
        shockcal.load_study(tmp_path)
    (tmp_path / "quick").symlink_to(results, target_is_directory=True)       # results/ after `make quick`
    with pytest.raises(InputError, match=f"studies below it: {tmp_path / 'quick'}$"):
        shockcal.load_study(tmp_path)
    partial = tmp_path / "partial"
    for part in ("posterior", "emulator", "features"):
        shutil.copytree(results / part, partial / part)
    (partial / "posterior" / "105S.nc").unlink()
    with pytest.raises(InputError) as caught:
        shockcal.load_study(partial)
    assert "posterior/105S.nc missing" in str(caught.value) and "\n" not in str(caught.value)


def test_readme_arviz_block_runs_as_written(quick_study, tmp_path, monkeypatch):
    """The README's "Posteriors in ArviZ" block as written, run where `make quick` leaves its results
    (results/quick, here a link to the session's quick study)."""
    import matplotlib

    matplotlib.use("Agg")
    results, _ = quick_study
    readme = (REPO / "README.md").read_text()
    section = readme.split("## Posteriors in ArviZ", 1)[1].split("\n## ", 1)[0]
    code = re.findall(r"```python\n(.*?)```", section, re.S)[0]
    assert 'load_study("results/quick")' in code
    (tmp_path / "results").mkdir()
    (tmp_path / "results" / "quick").symlink_to(results, target_is_directory=True)
    monkeypatch.chdir(tmp_path)
    scope: dict = {}
    exec(compile(code, "README.md", "exec"), scope)
    assert list(scope["summary"].index)[:2] == ["A_MPa", "B_MPa"]


def test_the_report_scores_the_emulator_on_the_posteriors_predictive_runs(quick_study):
    """report/emulator_heldout.csv: every feature of every shot, the overall row and the 12-feature region,
    on the predictive runs (no fit saw them); the overall RMSE is the root mean square of the per-feature ones."""
    results, _ = quick_study
    table = pd.read_csv(results / "report" / "emulator_heldout.csv")
    runs = len(pd.read_parquet(results / "predict" / "design.parquet"))
    features = table[~table["feature"].str.startswith(("all (", "region: "))]
    assert len(features) == 12 and (features["n_values"] == runs).all()
    overall = table[table["feature"] == f"all ({runs} runs)"].iloc[0]
    # the CSV keeps 6 significant digits
    assert overall["rmse_m_s"] == pytest.approx(np.sqrt(np.mean(features["rmse_m_s"] ** 2)), rel=1e-5)
    region = table[table["feature"] == "region: 104S+105S+106S (12 features)"].iloc[0]
    assert region["n_values"] == runs and 0 <= region["coverage"] <= 1
    assert (results / "report" / "emulator_heldout.html").is_file()
    sd = read_table_metadata(results / "posterior" / "joint.parquet")["observed_sd_m_s"]   # the joint's records' sd
    np.testing.assert_allclose(features["records_sd_m_s"], sd, rtol=1e-5)
    np.testing.assert_allclose(features["rmse_records_sd"], features["rmse_m_s"] / features["records_sd_m_s"], rtol=1e-5)
    assert overall["rmse_records_sd"] == pytest.approx(np.sqrt(np.mean(features["rmse_records_sd"] ** 2)), rel=1e-5)
