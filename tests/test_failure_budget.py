"""The features stage excludes failed runs and stops when too many of a shot's runs failed."""

from __future__ import annotations

import logging

import pandas as pd
import pytest

from shockcal.errors import ShockcalError
from shockcal.velocimetry.feature_tables import check_failures


def _table(n_runs: int, n_failed: int) -> pd.DataFrame:
    status = ["failed"] * n_failed + ["ok"] * (n_runs - n_failed)
    reason = [f"negative cell volume in cell {k}" for k in range(n_failed)] + [""] * (n_runs - n_failed)
    return pd.DataFrame({"run": range(n_runs), "status": status, "reason": reason})


def test_failures_within_budget_are_logged(caplog):
    with caplog.at_level(logging.WARNING):
        check_failures(_table(100, 5), 0.05, "104S")
    assert "5 of 100 runs failed and are excluded" in caplog.text


def test_too_many_failures_stop_with_the_runs_named():
    with pytest.raises(ShockcalError, match=r"shot 105S: 6 of 100 runs failed, more than the allowed 5%") as err:
        check_failures(_table(100, 6), 0.05, "105S")
    assert "run 0: negative cell volume in cell 0" in str(err.value)


def test_the_budget_holds_for_the_shot_not_for_one_chunk(tmp_path, monkeypatch, capsys):
    """The workflow extracts features per simulation chunk (`--no-failure-budget`) and checks the
    budget where the chunks merge (`--tables`): 4 failures in a chunk of 50 (8%) are 4% of the shot."""
    from pathlib import Path

    from shockcal.cli import main

    monkeypatch.chdir(Path(__file__).resolve().parents[1])       # the config's record paths are relative
    first, second = _table(50, 4), _table(50, 0).assign(run=lambda t: t["run"] + 50)
    paths = []
    for k, part in enumerate([second, first]):
        paths.append(str(tmp_path / f"chunk-{k}.parquet"))
        part.to_parquet(paths[-1])
    out = tmp_path / "104S.parquet"
    merge = ["features", "--config", "config/config.yaml", "--shot", "104S", "--out", str(out), "--tables"]
    assert main([*merge, *paths]) == 0
    merged = pd.read_parquet(out)
    assert merged["run"].tolist() == list(range(100)) and (merged["status"] == "failed").sum() == 4
    assert main([*merge, paths[1]]) == 2                         # the chunk alone is over the budget
    assert "4 of 50 runs failed, more than the allowed 5%" in capsys.readouterr().err
    assert main([*merge, paths[1], paths[1]]) == 2
    assert "run 0 is in more than one features table" in capsys.readouterr().err
