"""The `archive` simulator: FLAG's runs from the paper's data release as the training runs (config/flag-archive.yaml)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from shockcal.cli import main
from shockcal.velocimetry.columns import COLUMNS

REPO = Path(__file__).resolve().parents[1]


@pytest.fixture
def flag_config(paper_config, reference_data, tmp_path, monkeypatch):
    """config.yaml with config/flag-archive.yaml over it, written to a file; run from the repository."""
    overlay = yaml.safe_load((REPO / "config" / "flag-archive.yaml").read_text())
    paper_config.update(simulator=overlay["simulator"])
    path = tmp_path / "config.yaml"
    path.write_text(yaml.safe_dump(paper_config))
    monkeypatch.chdir(REPO)
    return path


def test_the_archive_design_is_flags_runs_with_features(flag_config, reference_data, tmp_path):
    assert main(["design", "--config", str(flag_config), "--out", str(tmp_path / "design.parquet")]) == 0
    design = pd.read_parquet(tmp_path / "design.parquet")
    flag = pd.read_csv(reference_data / "design.csv")
    assert design["run"].tolist() == list(range(500))
    columns = list(flag.columns)
    assert np.array_equal(design[columns].to_numpy(), flag.iloc[:500][columns].to_numpy())


def test_archived_features_reach_the_features_table_unchanged(flag_config, reference_data, tmp_path):
    pd.read_csv(reference_data / "design.csv").iloc[10:14].to_csv(tmp_path / "design.csv", index=False)
    chunk, features = tmp_path / "chunk.parquet", tmp_path / "features.parquet"
    assert main(["simulate", "--config", str(flag_config), "--shot", "105S", "--design", str(tmp_path / "design.csv"),
                 "--out", str(chunk)]) == 0
    assert main(["features", "--config", str(flag_config), "--shot", "105S", "--traces", str(chunk),
                 "--out", str(features)]) == 0
    ours = pd.read_parquet(features)
    flag = pd.read_csv(reference_data / "flag_features_105S.csv").iloc[10:14].reset_index(drop=True)
    assert ours["status"].eq("ok").all() and ours["run"].tolist() == flag["run"].tolist()
    assert np.array_equal(ours[COLUMNS].to_numpy(), flag[COLUMNS].to_numpy())


def test_a_run_the_archive_does_not_hold_is_a_failed_row(flag_config, reference_data, tmp_path):
    """A posterior draw numbered like an archived run (the run set predict) is not given that run's features."""
    design = pd.read_csv(reference_data / "design.csv").iloc[:2]
    design.loc[1, "A"] *= 1.01
    design.to_csv(tmp_path / "design.csv", index=False)
    chunk = tmp_path / "chunk.parquet"
    assert main(["simulate", "--config", str(flag_config), "--shot", "104S", "--design", str(tmp_path / "design.csv"),
                 "--out", str(chunk)]) == 0
    table = pd.read_parquet(chunk)
    assert table["status"].tolist() == ["ok", "failed"]
    assert table["reason"].iloc[1].startswith("archive: output missing: run 1 has A = ")
    assert table["reason"].iloc[1].endswith(": not an archived run")
