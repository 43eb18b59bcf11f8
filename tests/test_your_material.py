"""The worked example of docs/your_material.md at toy size: a copper study from `shockcal init` through the
edit of its config to the joint posterior and the report, with records written by
examples/copper/make_records.py (a few minutes on 2 cores)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest
import yaml

from shockcal.cli import main
from shockcal.study.config_files import FILL_IN

REPO = Path(__file__).resolve().parents[1]
EXAMPLE = REPO / "examples" / "copper"
SNAKEMAKE = str(Path(sys.executable).parent / "snakemake")
# the truth the records are made at (examples/copper/make_records.py), in the config's units
TRUTH = {"A": 90e-5, "B": 292e-5, "C": 0.025, "n": 0.31, "m": 1.09}


def edit(path: Path, records: Path) -> int:
    """The worked example's edit of the init config at `path`: the sections examples/copper/config.yaml
    fills in (its material is init's), its records in `records`. Returns the number of placeholders it replaced."""
    text = path.read_text()
    config = yaml.safe_load(text)
    example = yaml.safe_load((EXAMPLE / "config.yaml").read_text())
    assert config["material"] == example["material"] == {"name": "copper"}
    for section in ("hydro", "shots", "inputs"):
        config[section] = example[section]
    config["observed"]["records"] = {shot: {"path": str(records / f"{shot}.txt")} for shot in example["shots"]}
    path.write_text(yaml.safe_dump(config, sort_keys=False))
    assert FILL_IN not in path.read_text() and "<shot>" not in path.read_text()
    return sum(FILL_IN in line and not line.lstrip().startswith("#") for line in text.splitlines())


@pytest.mark.slow
def test_a_copper_study_from_init_to_the_joint_posterior_and_the_report(tmp_path):
    study = tmp_path / "copper"
    assert main(["init", str(study), "--material", "copper"]) == 0
    records = study / "records"
    subprocess.run([sys.executable, str(EXAMPLE / "make_records.py"), "--out", str(records)], cwd=REPO, check=True)
    assert edit(study / "config.yaml", records) > 0
    toy = yaml.safe_load((EXAMPLE / "toy.yaml").read_text())
    results = tmp_path / "results"
    toy.update(extends=str(study / "config.yaml"), study={"results_dir": str(results)})
    (study / "toy.yaml").write_text(yaml.safe_dump(toy))
    for args in (["--cores", "2", "all"], ["--report", str(results / "report.html"), "all"]):
        done = subprocess.run([SNAKEMAKE, *args, "--configfile", str(study / "toy.yaml")], cwd=REPO,
                              capture_output=True, text=True)
        assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    joint = pd.read_parquet(results / "posterior" / "joint.parquet")
    box = yaml.safe_load((EXAMPLE / "config.yaml").read_text())["inputs"]
    for name, truth in TRUTH.items():
        assert joint[name].between(box[name]["min"], box[name]["max"]).all(), name
        assert joint[name].min() < truth < joint[name].max(), name            # the truth inside the draws' range
    assert (results / "posterior" / "joint.nc").is_file()
    report = (results / "report.html").read_text(errors="replace")
    assert "Cu300" in report and "Cu500" in report
