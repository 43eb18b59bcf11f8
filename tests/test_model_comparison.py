"""The strength laws' evidence table (shockcal.model_comparison, `shockcal compare-models`)."""

from __future__ import annotations

import math
import subprocess
import sys

import pandas as pd
import pytest

from shockcal.errors import InputError
from shockcal.io import write_table
from shockcal.model_comparison import COLUMNS, ModelResult, evidence_table

OBSERVED = (69.7, 199.4, 79.5, 186.4)


def test_bayes_factors_against_johnson_cook():
    table = evidence_table({
        "johnson-cook": ModelResult(("A", "B"), -45.0, 0.03, OBSERVED, 12.0, 20.0),
        "steinberg-guinan": ModelResult(("Y0_GPa", "n", "V1"), -43.5, 0.04, OBSERVED, 10.0, 15.0),
    })
    assert list(table.columns) == COLUMNS
    sg = table.set_index("model").loc["steinberg-guinan"]
    assert sg["log_bf_vs_johnson_cook"] == pytest.approx(1.5)
    assert sg["log_bf_sd"] == pytest.approx(0.05)                       # 0.03 and 0.04 in quadrature
    assert sg["n_params"] == 3
    assert table.set_index("model").loc["johnson-cook", "log_bf_vs_johnson_cook"] == 0.0


def test_evidences_of_other_data_do_not_compare():
    with pytest.raises(InputError, match="ptw was calibrated on other measured features"):
        evidence_table({"johnson-cook": ModelResult(("A",), -45.0, 0.03, OBSERVED, 12.0, 20.0),
                        "ptw": ModelResult(("s0",), -40.0, 0.03, (*OBSERVED[:3], 187.0), 12.0, 20.0)})
    with pytest.raises(InputError, match="no johnson-cook study"):
        evidence_table({"ptw": ModelResult(("s0",), -40.0, 0.03, OBSERVED, 12.0, 20.0)})


def _study(tmp_path, name, log_z, sd, kfold, outer=None):
    root = tmp_path / name
    write_table(pd.DataFrame({"x": [0.0]}), root / "posterior" / "joint.parquet",
                {"table": "posterior samples", "parameters": ["a", "b"], "log_evidence": log_z,
                 "log_evidence_sd": sd, "observed": str(list(OBSERVED))})
    (root / "emulator").mkdir(parents=True)
    (root / "emulator" / "cv_rmse.csv").write_text(
        "scheme,shot,feature,rmse_m_s,bias_m_s,coverage90\n"
        f"kfold,104S,v_elastic,99,0,0.9\nkfold,all,all,{kfold},0,0.9\n"
        + ("" if outer is None else f"outer,all,all,{outer},0,0.8\n"))
    return root


def test_command_reads_each_study(tmp_path):
    jc = _study(tmp_path, "jc", -45.0, 0.03, 12.4, 21.0)
    za = _study(tmp_path, "za", -47.0, 0.04, 11.0, 19.0)
    ptw = _study(tmp_path, "ptw", -46.0, 0.05, 30.0)                   # no outer check: too few runs inside
    out = tmp_path / "models" / "evidence.csv"
    done = subprocess.run([sys.executable, "-m", "shockcal", "compare-models", "--model", f"jc={jc}",
                           "--model", f"zerilli-armstrong={za}", "--model", f"ptw={ptw}", "--out", str(out)],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    table = pd.read_csv(out).set_index("model")
    assert table.loc["zerilli-armstrong", "log_bf_vs_johnson_cook"] == pytest.approx(-2.0)
    assert table.loc["zerilli-armstrong", "kfold_rmse_m_s"] == 11.0
    assert table.loc["zerilli-armstrong", "log_bf_sd"] == pytest.approx(math.hypot(0.03, 0.04))
    assert math.isnan(table.loc["ptw", "outer_rmse_m_s"]) and "ptw" in done.stderr and "no outer check" in done.stderr
    missing = subprocess.run([sys.executable, "-m", "shockcal", "compare-models", "--model", f"jc={jc}",
                              "--model", f"ptw={tmp_path / 'nowhere'}", "--out", str(out)], capture_output=True, text=True)
    assert missing.returncode != 0
    assert "--model ptw:" in missing.stderr and "joint.parquet does not exist" in missing.stderr
    assert "Traceback" not in missing.stderr
