"""Shared fixtures: the study config, the paper's reference data (skipped when absent) and one quick study."""

from __future__ import annotations

import copy
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

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


@pytest.fixture(scope="session")
def quick_study(tmp_path_factory) -> tuple[Path, Path]:
    """The quick study (config/quick.yaml, about two minutes on 2 idle cores) run once per session, end to
    end, into a temporary results directory: (that directory, the config overlay naming it). Tests that
    need a finished study read it; none may change it for good."""
    root = tmp_path_factory.mktemp("quick")
    results, overlay = root / "results", root / "results.yaml"
    overlay.write_text(yaml.safe_dump({"study": {"results_dir": str(results)}}))
    snakemake = str(Path(sys.executable).parent / "snakemake")
    done = subprocess.run([snakemake, "all", "--cores", "2", "--configfile", "config/quick.yaml", str(overlay)],
                          cwd=REPO, capture_output=True, text=True)
    if done.returncode != 0:
        pytest.fail(f"the quick study failed:\n{done.stdout[-3000:]}\n{done.stderr[-3000:]}")
    return results, overlay
