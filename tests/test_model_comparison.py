"""The strength laws' evidence table (shockcal.campaign.model_comparison, `shockcal compare-models`)."""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest

from shockcal.campaign.box_sensitivity import BoxSensitivity
from shockcal.campaign.model_comparison import COLUMNS, ModelResult, evidence_table
from shockcal.cli import main
from shockcal.errors import InputError
from shockcal.io import write_table

OBSERVED = (69.7, 199.4, 79.5, 186.4)
BOX = BoxSensitivity(2, -46.0, 0.1, -47.5, 0.2)


def test_bayes_factors_against_the_first_law_or_the_named_one():
    results = {"johnson-cook": ModelResult(("A", "B"), -45.0, 0.03, OBSERVED, 12.0, 20.0, BOX),
               "steinberg-guinan": ModelResult(("Y0_GPa", "n", "V1"), -43.5, 0.04, OBSERVED, 10.0, 15.0, BOX)}
    against_sg = evidence_table(results, "steinberg-guinan").set_index("model")
    assert against_sg.loc["johnson-cook", "log_bf_vs_reference"] == pytest.approx(-1.5)
    assert set(against_sg["reference_model"]) == {"steinberg-guinan"} and against_sg.loc["steinberg-guinan", "log_bf_sd"] == 0
    table = evidence_table(results)
    assert list(table.columns) == COLUMNS
    sg = table.set_index("model").loc["steinberg-guinan"]
    assert sg["log_bf_vs_reference"] == pytest.approx(1.5) and sg["reference_model"] == "johnson-cook"
    assert sg["log_bf_sd"] == pytest.approx(0.05)                       # 0.03 and 0.04 in quadrature
    assert sg["n_params"] == 3
    assert table.set_index("model").loc["johnson-cook", "log_bf_vs_reference"] == 0.0
    assert (sg["n_box_params"], sg["log_z_box_half"], sg["log_z_box_half_sd"], sg["log_z_box_double"],
            sg["posterior_mass_near_faces"]) == tuple(BOX)


def test_evidences_of_other_data_do_not_compare():
    with pytest.raises(InputError, match="ptw was calibrated on other measured features"):
        evidence_table({"johnson-cook": ModelResult(("A",), -45.0, 0.03, OBSERVED, 12.0, 20.0, BOX),
                        "ptw": ModelResult(("s0",), -40.0, 0.03, (*OBSERVED[:3], 187.0), 12.0, 20.0, BOX)})
    with pytest.raises(InputError, match="the reference law johnson-cook is not among the laws given \\(ptw\\)"):
        evidence_table({"ptw": ModelResult(("s0",), -40.0, 0.03, OBSERVED, 12.0, 20.0, BOX)}, "johnson-cook")


def _study(tmp_path, name, log_z, sd, kfold, outer=None):
    """A study's files as compare-models reads them: inputs a (Mbar, box [0, 2]) and the velocity V1 (cm/us),
    four weighted draws, one inside a's half box [0.5, 1.5] with weight 0.4."""
    root = tmp_path / name
    meta = {"parameters": ["V1", "a"], "log_evidence": log_z, "log_evidence_sd": sd, "observed": str(list(OBSERVED)),
            "units": {"a": "Mbar", "V1": "cm/us", "lambda_y": "-"}}
    write_table(pd.DataFrame({"x": [0.0]}), root / "posterior" / "joint.parquet", {"table": "posterior samples", **meta})
    write_table(pd.DataFrame({"V1": [0.02] * 4, "a": [0.05, 1.0, 1.6, 1.95], "lambda_y": 1.0,
                              "log_weight": np.log([0.1, 0.4, 0.2, 0.3]), "log_likelihood": 0.0}),
                root / "posterior" / "joint_weighted.parquet", {"table": "posterior weighted draws", **meta})
    (root / "emulator").mkdir(parents=True)
    (root / "emulator" / "emulator.json").write_text(json.dumps({"input_bounds": {"a": [0.0, 2.0], "V1": [0.01, 0.03]}}))
    (root / "emulator" / "cv_rmse.csv").write_text(
        "scheme,shot,feature,rmse_m_s,bias_m_s,coverage90\n"
        f"kfold,104S,v_elastic,99,0,0.9\nkfold,all,all,{kfold},0,0.9\n"
        + ("" if outer is None else f"outer,all,all,{outer},0,0.8\n"))
    return root


def compare_models(capsys, *args) -> tuple[int, str]:
    """`shockcal compare-models ARGS` in this process (a `python -m shockcal` costs seconds of imports):
    its exit code and what it printed to stderr."""
    code = main(["compare-models", *map(str, args)])
    return code, capsys.readouterr().err


def test_command_reads_each_study(tmp_path, capsys, caplog):
    jc = _study(tmp_path, "jc", -45.0, 0.03, 12.4, 21.0)
    za = _study(tmp_path, "za", -47.0, 0.04, 11.0, 19.0)
    ptw = _study(tmp_path, "ptw", -46.0, 0.05, 30.0)                   # no outer check: too few runs inside
    out = tmp_path / "models" / "evidence.csv"
    with caplog.at_level("WARNING"):
        code, err = compare_models(capsys, "--model", f"jc={jc}", "--model", f"zerilli-armstrong={za}", "--model",
                                   f"ptw={ptw}", "--out", out, "--figures-dir", tmp_path / "models" / "figures")
    assert code == 0, err
    assert (tmp_path / "models" / "figures" / "evidence.png").is_file()
    table = pd.read_csv(out).set_index("model")
    za_row = table.loc["zerilli-armstrong"]
    assert za_row["n_box_params"] == 1                                  # a; V1 (cm/us) is a shot's velocity
    assert za_row["log_z_box_half"] == pytest.approx(-47.0 + math.log(2) + math.log(0.4))
    assert za_row["log_z_box_half_sd"] == pytest.approx(math.hypot(0.04, math.sqrt(
        0.1**2 * 0.4**2 + 0.4**2 * 0.6**2 + 0.2**2 * 0.4**2 + 0.3**2 * 0.4**2) / 0.4))
    assert za_row["log_z_box_double"] == pytest.approx(-47.0 - math.log(3 / 2))   # [0, 2] -> [0, 3]: clipped at 0
    assert za_row["posterior_mass_near_faces"] == pytest.approx(0.3)               # a = 1.95 > 1.9; 0.05 is near a face at its floor
    assert table.loc["zerilli-armstrong", "log_bf_vs_reference"] == pytest.approx(-2.0)
    assert table.loc["zerilli-armstrong", "kfold_rmse_m_s"] == 11.0
    assert table.loc["zerilli-armstrong", "log_bf_sd"] == pytest.approx(math.hypot(0.03, 0.04))
    assert math.isnan(table.loc["ptw", "outer_rmse_m_s"]) and "ptw" in caplog.text and "no outer check" in caplog.text
    assert table["heldout_rmse_m_s"].isna().all() and table["heldout_coverage"].isna().all()   # no predictive runs
    code, err = compare_models(capsys, "--model", f"jc={jc}", "--model", f"ptw={tmp_path / 'nowhere'}", "--out", out)
    assert code != 0
    assert "--model ptw:" in err and "joint.parquet does not exist" in err
    assert "Traceback" not in err
    (za / "emulator" / "emulator.json").write_text(json.dumps({"input_bounds": {"V1": [0.01, 0.03]}}))
    code, err = compare_models(capsys, "--model", f"jc={jc}", "--model", f"za={za}", "--out", out)
    assert code != 0 and "Traceback" not in err
    assert "--model zerilli-armstrong:" in err and "input_bounds has no a" in err
    (za / "emulator" / "emulator.json").write_text("{not json")
    code, err = compare_models(capsys, "--model", f"jc={jc}", "--model", f"za={za}", "--out", out)
    assert code != 0 and "Traceback" not in err
    assert "emulator.json: not an emulator's JSON description" in err


def test_the_emulator_on_each_laws_predictive_runs_joins_its_row(tmp_path, capsys, caplog):
    """A study with report/emulator_heldout.csv (the emulator on its posterior's predictive runs): its overall row's
    RMSE and band coverage; a table without that row is one line naming the file."""
    jc = _study(tmp_path, "jc", -45.0, 0.03, 12.4, 21.0)
    (jc / "report").mkdir()
    (jc / "report" / "emulator_heldout.csv").write_text(
        "feature,rmse_m_s,coverage,mean_z2,n_values,block,n_features,n_runs\n"
        "104S:v_elastic,1.5,0.95,0.8,99,,,\nall (99 runs),2.79,0.928,0.9,1188,,,\n"
        ",,0.9,,,104S+105S+106S,12,99\n")
    out = tmp_path / "evidence.csv"
    code, err = compare_models(capsys, "--model", f"johnson-cook={jc}", "--out", out)
    assert code == 0, err
    row = pd.read_csv(out).iloc[0]
    assert row["heldout_rmse_m_s"] == 2.79 and row["heldout_coverage"] == 0.928
    (jc / "report" / "emulator_heldout.csv").write_text("feature,rmse_m_s,coverage\n104S:v_elastic,1.5,0.95\n")
    with caplog.at_level("INFO"):                      # the one line is all it prints: no log line either
        code, err = compare_models(capsys, "--model", f"johnson-cook={jc}", "--out", out)
    assert code != 0 and len(err.strip().splitlines()) == 1 and not caplog.records
    assert "emulator_heldout.csv: no 'all (N runs)' row" in err
