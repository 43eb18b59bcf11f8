"""Every table says which shockcal and which commit wrote it, and stays the same bytes between runs."""

import shutil
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

import shockcal
from shockcal.io import read_table_metadata, write_table
from shockcal.provenance import git_state, provenance

SOURCE = Path(shockcal.__file__).resolve().parent


def git(*args):
    return subprocess.run(["git", "-C", str(SOURCE), *args], capture_output=True, text=True, check=True).stdout.strip()


def test_every_table_carries_version_and_commit(tmp_path):
    write_table(pd.DataFrame({"run": [0]}), tmp_path / "with.parquet", {"table": "design"})
    write_table(pd.DataFrame({"run": [0]}), tmp_path / "without.parquet")
    for name in ("with", "without"):
        meta = read_table_metadata(tmp_path / f"{name}.parquet")["provenance"]
        assert meta == provenance() and meta["shockcal_version"] == shockcal.__version__
    assert read_table_metadata(tmp_path / "with.parquet")["table"] == "design"


@pytest.mark.skipif(shutil.which("git") is None, reason="git is not installed")
def test_commit_is_the_checkouts_short_hash_with_its_dirty_flag():
    try:
        head = git("rev-parse", "--short", "HEAD")
    except subprocess.CalledProcessError:
        pytest.skip("the package is not in a git checkout")
    dirty = bool(git("status", "--porcelain", "--untracked-files=no"))
    assert git_state(SOURCE) == {"git_commit": head, "git_dirty": dirty}


def test_unknown_without_git_or_outside_a_checkout(tmp_path, monkeypatch):
    (tmp_path / "__init__.py").write_text("")                   # an installed copy: no repository around it
    assert git_state(tmp_path) == {"git_commit": "unknown", "git_dirty": None}
    monkeypatch.setenv("PATH", str(tmp_path))                   # no git at all
    assert git_state(SOURCE) == {"git_commit": "unknown", "git_dirty": None}


def test_two_processes_of_one_checkout_write_the_same_bytes(tmp_path):
    """The provenance is fixed for a checkout, so a table rewritten by another run is byte-identical."""
    code = ("import sys, pandas as pd; from shockcal.io import write_table; "
            "write_table(pd.DataFrame({'run': [0, 1], 'v_m_s': [1.5, 2.5]}), sys.argv[1], {'units': {'v_m_s': 'm/s'}})")
    for name in ("a.parquet", "b.parquet"):
        subprocess.run([sys.executable, "-c", code, str(tmp_path / name)], check=True)
    assert (tmp_path / "a.parquet").read_bytes() == (tmp_path / "b.parquet").read_bytes()
