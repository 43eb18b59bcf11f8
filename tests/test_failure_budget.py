"""The features stage excludes failed runs and stops when too many of a shot's runs failed."""

from __future__ import annotations

import logging

import pandas as pd
import pytest

from shockcal.errors import ShockcalError
from shockcal.features import check_failures


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
