"""Shared fixtures: the study config, the paper's reference data (skipped when absent) and one quick study."""

from __future__ import annotations

import copy
import os
import shutil
import signal
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest
import yaml

from shockcal.reference import reference_dir
from shockcal.study.read_log import READ_LOG
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


class BackgroundStudy:
    """The quick study (config/quick.yaml, about two minutes on 2 idle cores) run end to end by snakemake
    in the background, into a temporary results directory, from the end of collection on: the tests that
    do not need it run meanwhile (pytest uses one core, the study's jobs the other)."""

    def __init__(self, root: Path):
        self.results, self.overlay, self.log = root / "results", root / "results.yaml", root / "snakemake.log"
        self.overlay.write_text(yaml.safe_dump({"study": {"results_dir": str(self.results)}}))
        snakemake = str(Path(sys.executable).parent / "snakemake")
        with self.log.open("w") as log:  # each command logs the keys of its config slice that it reads
            self.process = subprocess.Popen([snakemake, "all", "--cores", "2", "--configfile", "config/quick.yaml",
                                             str(self.overlay)], cwd=REPO, stdout=log, stderr=subprocess.STDOUT,
                                            start_new_session=True, env={**os.environ, READ_LOG: str(read_log(root))})

    def wait(self) -> tuple[Path, Path]:
        """(the results directory, the config overlay naming it) once the study has finished; the test
        fails with the end of snakemake's output when it did not."""
        if self.process.wait() != 0:
            pytest.fail(f"the quick study failed:\n{self.log.read_text()[-6000:]}")
        return self.results, self.overlay

    def stop(self) -> None:
        """Stop the study and its jobs when the session ends before it (an error with -x, Ctrl-C)."""
        if self.process.poll() is None:
            os.killpg(self.process.pid, signal.SIGTERM)
            self.process.wait()


QUICK_STUDY = pytest.StashKey[BackgroundStudy]()


def read_log(root: Path) -> Path:
    """The folder where the quick study's commands log which keys of their config slices they read
    (`shockcal.study.read_log`), beside its results."""
    return root / "reads"


@pytest.fixture(scope="session")
def quick_study_reads(quick_study) -> Path:
    """The finished quick study's read log: one JSON file per command (`shockcal.study.read_log`)."""
    return read_log(quick_study[0].parent)


@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(items):
    """Mark `workflow` every test that needs the quick study (directly or through another fixture), before
    `-m` selects: `make test` runs the others on pytest-xdist workers, `make test-workflow` these."""
    for item in items:
        if "quick_study" in item.fixturenames:
            item.add_marker(pytest.mark.workflow)


def pytest_collection_finish(session):
    """Start the quick study as soon as the tests are known, when one of them needs it."""
    if any("quick_study" in item.fixturenames for item in session.items):
        root = Path(tempfile.mkdtemp(prefix="shockcal-quick-"))
        session.config.stash[QUICK_STUDY] = BackgroundStudy(root)


def pytest_sessionfinish(session):
    study = session.config.stash.get(QUICK_STUDY, None)
    if study is not None:
        study.stop()
        shutil.rmtree(study.results.parent, ignore_errors=True)


@pytest.fixture(scope="session")
def quick_study(request) -> tuple[Path, Path]:
    """The finished quick study (`BackgroundStudy`): (its results directory, the config overlay naming
    it). Tests that need a finished study read it; none may change it for good."""
    return request.config.stash[QUICK_STUDY].wait()
