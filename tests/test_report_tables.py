"""`shockcal report-tables`: the report's tables as CSV and HTML from the posteriors, the CV table, the
coverage checks and the Sobol table, and the records' sd the held-out table reads its error in."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from shockcal.cli import main
from shockcal.cli.report import posterior_records_sd
from shockcal.errors import InputError
from shockcal.io import write_table


def test_report_tables_from_posteriors_cv_coverage_and_sobol(tmp_path):
    posterior = tmp_path / "joint.parquet"
    write_table(pd.DataFrame({"A": [0.002], "lambda_y": [1.0], "log_likelihood": [-3.0]}), posterior,
                {"shots": ["104S", "105S"], "log_evidence": -45.25, "log_evidence_sd": 0.04, "ess_kish": 430.0,
                 "likelihood_evaluations": 6800, "retained": 1, "distinct_draws": 1})
    write_table(pd.DataFrame({"parameter": ["A"], "unit": ["Mbar"], "mean": [0.002], "q05": [0.001]}),
                tmp_path / "joint_summary.parquet")
    pd.DataFrame({"scheme": ["loo_closed_form"], "shot": ["all"], "rmse_m_s": [3.1]}).to_csv(tmp_path / "cv.csv",
                                                                                              index=False)
    rng = np.random.default_rng(0)
    trials = pd.DataFrame({"trial": np.repeat(np.arange(20), 2), "parameter": ["A", "B"] * 20,
                           "truth": rng.uniform(size=40), "q05": 0.05, "q95": 0.95, "ess": 500.0})
    trials["inside"] = trials["truth"].between(trials["q05"], trials["q95"])
    write_table(trials, tmp_path / "coverage_emulator.parquet")
    pd.DataFrame({"domain": ["prior"], "shot": ["104S"], "feature": ["v_elastic"], "input": ["A"], "S1": [0.8],
                  "S1_conf": [0.07], "ST": [0.82], "ST_conf": [0.06]}).to_csv(tmp_path / "sobol.csv", index=False)
    out = tmp_path / "report"
    assert main(["report-tables", "--posteriors", f"joint={posterior}", "--cv-rmse", str(tmp_path / "cv.csv"),
                 "--coverage", f"emulator={tmp_path / 'coverage_emulator.parquet'}", "--sobol",
                 str(tmp_path / "sobol.csv"), "--out-dir", str(out)]) == 0
    assert sorted(p.name for p in out.iterdir()) == [
        "coverage.csv", "coverage.html", "cross_validation.csv", "cross_validation.html", "evidence.csv",
        "evidence.html", "posterior_summary.csv", "posterior_summary.html", "sobol.html"]
    evidence = pd.read_csv(out / "evidence.csv")
    assert evidence.loc[0, "calibration"] == "joint" and evidence.loc[0, "log_evidence"] == -45.25
    assert evidence.loc[0, "shots"] == "104S+105S"
    assert pd.read_csv(out / "posterior_summary.csv").columns[0] == "calibration"
    coverage = pd.read_csv(out / "coverage.csv")
    assert list(coverage["parameter"]) == ["A", "B"] and (coverage["truth"] == "emulator").all()
    assert "<table" in (out / "sobol.html").read_text() and "-45.25" in (out / "evidence.html").read_text()


def test_heldout_options_go_together_in_one_line(tmp_path, capsys):
    assert main(["report-tables", "--heldout-emulator", str(tmp_path), "--out-dir", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.endswith("--heldout-emulator, --heldout-design and --heldout-features go together") and "\n" not in err


def test_the_records_sd_comes_from_a_posteriors_metadata_in_the_held_out_tables_shot_order(tmp_path):
    """`posterior_records_sd`: the sd the posterior was calibrated with, reordered to the held-out features' shots;
    a table without it, or a shot the posterior lacks, is an InputError naming the file."""
    posterior = tmp_path / "joint.parquet"
    features = ["v_elastic", "v_plastic"]
    write_table(pd.DataFrame({"A": [0.002]}), posterior,
                {"shots": ["104S", "105S"], "observed": [60.0, 200.0, 65.0, 350.0], "observed_sd_m_s": [1, 2, 3, 4]})
    np.testing.assert_allclose(posterior_records_sd(str(posterior), ["105S", "104S"], features), [3, 4, 1, 2], rtol=1e-12)
    with pytest.raises(InputError, match="without 106S"):
        posterior_records_sd(str(posterior), ["104S", "106S"], features)
    write_table(pd.DataFrame({"A": [0.002]}), tmp_path / "plain.parquet", {"shots": ["104S"]})
    with pytest.raises(InputError, match="plain.parquet: not a posterior written by `shockcal calibrate`"):
        posterior_records_sd(str(tmp_path / "plain.parquet"), ["104S"], features)
