"""Shared fixtures: the study config and the paper's reference data (skipped when absent)."""

from __future__ import annotations

import copy
from pathlib import Path

import pytest

from shockcal.reference import reference_dir
from shockcal.study.validate import load_config

REPO = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="session")
def paper_config_readonly() -> dict:
    return load_config(REPO / "config" / "config.yaml")


@pytest.fixture
def paper_config(paper_config_readonly) -> dict:
    """The paper's study config (a fresh copy each test may modify)."""
    return copy.deepcopy(paper_config_readonly)


@pytest.fixture(scope="session")
def reference_data() -> Path:
    """../shared/data/al5083 (the paper's data release); skips the test when not on this machine."""
    path = reference_dir()
    if path is None:
        pytest.skip("reference data (../shared/data/al5083) not found; set SHOCKCAL_REFERENCE_DATA to run this test")
    return path
