"""`make models` and its sizes (models-reduced, models-quick): each law's study to its joint posterior and
posterior predictive runs, then the evidence table, release.csv and the figures (docs/models.md)."""

from __future__ import annotations

import math
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

from shockcal.campaign.model_comparison import COLUMNS
from shockcal.campaign.release import RELEASE_COLUMNS

REPO = Path(__file__).resolve().parents[1]
SNAKEMAKE = str(Path(sys.executable).parent / "snakemake")


def make_dry_run(target: str, **variables) -> str:
    """The commands `make -n target` prints (recursive makes included), with the given make variables."""
    return subprocess.run(["make", "-n", "-o", ".venv/.installed", target, *(f"{k}={v}" for k, v in variables.items())],
                          cwd=REPO, capture_output=True, text=True, check=True).stdout


def law_command(printed: str, law: str) -> list[str]:
    """The snakemake call of the Makefile's per-law target (model-study-<law>), without its console prefix."""
    line = next(line for line in printed.replace("\\\n", " ").splitlines() if f"strength={{model: {law}}}" in line)
    return shlex.split(line.removeprefix("set -o pipefail; ").split(" 2>&1 |")[0])


def cores_of(command: list[str]) -> str:
    """The --cores a snakemake call is given."""
    return command[command.index("--cores") + 1]


def test_models_run_the_laws_side_by_side(tmp_path):
    """`make models` runs one make job per law, the costliest first, each line of its console prefixed with the
    law. The machine's cores are split between up to four laws: on 2 cores two at a time with one core each, on
    8 four with two each; `MODEL_JOBS=1` runs one law after another on every core."""
    printed = make_dry_run("models-quick", MODELS="johnson-cook ptw zerilli-armstrong", CORES=2).replace("\\\n", " ")
    assert re.search(r"-j 2 +model-study-ptw model-study-johnson-cook model-study-zerilli-armstrong", printed)
    assert "sed -u 's/^/[ptw] /'" in printed
    assert {cores_of(law_command(printed, law)) for law in ("johnson-cook", "ptw", "zerilli-armstrong")} == {"1"}
    printed = make_dry_run("models-quick", CORES=8)
    assert re.search(r"-j 4 ", printed.replace("\\\n", " ")) and cores_of(law_command(printed, "ptw")) == "2"
    one_by_one = make_dry_run("models", MODELS="johnson-cook ptw", MODEL_JOBS=1, CORES=2)
    assert re.search(r"-j 1 \\\s+model-study-ptw", one_by_one) and cores_of(law_command(one_by_one, "ptw")) == "2"


def test_models_reduced_runs_each_law_to_its_predictive_runs(tmp_path):
    """`make models-reduced`: config/models-reduced.yaml over the paper's config, each law to posterior/joint.nc
    (so its predict run set: 30 draws per shot in chunks of 25), and model-predictions reading the paper's config."""
    printed = make_dry_run("models-reduced", MODELS="johnson-cook ptw", MODELS_DIR=tmp_path)
    command = law_command(printed, "ptw")
    assert command[command.index("--configfile") + 1:][:2] == ["config/config.yaml", "config/models-reduced.yaml"]
    assert command[-3:] == ["--", f"{tmp_path}/ptw/posterior/joint.nc", f"{tmp_path}/ptw/report/emulator_heldout.csv"]
    assert f"--config config/config.yaml --model johnson-cook={tmp_path}/johnson-cook --model ptw={tmp_path}/ptw" in printed
    assert f"--out {tmp_path}/release.csv" in printed and f"--out {tmp_path}/evidence.csv" in printed
    dry = subprocess.run([SNAKEMAKE, "--dry-run", *command[1:]], cwd=REPO, capture_output=True, text=True)
    assert dry.returncode == 0, dry.stdout[-2000:] + dry.stderr[-2000:]
    predict_chunks = re.findall(r"^rule simulate:\n(?:\s+.*\n)*?\s+wildcards: run_set=predict", dry.stdout, flags=re.M)
    assert len(predict_chunks) == 3 * 2                             # 3 shots x ceil(30 / 25) chunks
    assert "rule posterior_netcdf:" in dry.stdout and "rule report_heldout:" in dry.stdout


@pytest.mark.slow   # 4 s; the Makefile's wiring is the same as models-reduced's (the test above)
def test_models_runs_each_law_in_waves_and_models_paper_on_the_papers_design(tmp_path):
    """`make models`: config/sequential.yaml over the paper's config, each law's runs in waves (its steps'
    emulators and posteriors), to its joint posterior and its emulator scored on the predictive runs; `make
    models-paper`: the paper's config alone, into results/models-paper."""
    printed = make_dry_run("models", MODELS="johnson-cook ptw", MODELS_DIR=tmp_path)
    command = law_command(printed, "ptw")
    assert command[command.index("--configfile") + 1:][:3] == ["config/config.yaml", "config/sequential.yaml", "--config"]
    dry = subprocess.run([SNAKEMAKE, "--dry-run", *command[1:]], cwd=REPO, capture_output=True, text=True)
    assert dry.returncode == 0, dry.stdout[-2000:] + dry.stderr[-2000:]
    for rule in ("wave_design", "wave_calibrate", "report_heldout"):
        assert f"rule {rule}:" in dry.stdout, rule
    waves = re.findall(r"wildcards: run_set=wave(\d), shot=", dry.stdout)
    assert sorted(set(waves)) == ["1", "2"]
    paper = law_command(make_dry_run("models-paper", MODELS="ptw"), "ptw")
    assert paper[paper.index("--configfile") + 1:][:2] == ["config/config.yaml", "--config"]
    assert "study={results_dir: results/models-paper/ptw}" in paper


def test_models_quick_is_the_paper_config_with_the_quick_overlay(tmp_path):
    printed = make_dry_run("models-quick")
    command = law_command(printed, "johnson-cook")
    assert command[command.index("--configfile") + 1:][:2] == ["config/config.yaml", "config/quick.yaml"]
    assert "results/models-quick/evidence.csv" in printed and "results/models-quick/release.csv" in printed


@pytest.mark.slow   # two quick studies with their predictive runs: 6.3 min on 2 cores at load 3-6 (2026-11-26)
def test_models_at_toy_size_end_to_end(tmp_path):
    """`make models` as models-quick runs it, for Johnson-Cook and Steinberg-Guinan (a law with its own G law and
    no per-shot modulus inputs): evidence.csv with the box columns, release.csv per law and shot, the figures."""
    done = subprocess.run(["make", "-o", ".venv/.installed", "models", "MODELS=johnson-cook steinberg-guinan",
                           "MODELS_CONFIG=config/config.yaml config/quick.yaml", f"MODELS_DIR={tmp_path}", "CORES=2"],
                          cwd=REPO, capture_output=True, text=True)
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    evidence = pd.read_csv(tmp_path / "evidence.csv").set_index("model")
    assert list(evidence.reset_index().columns) == COLUMNS
    assert evidence.loc["johnson-cook", "n_box_params"] == 8 and evidence.loc["steinberg-guinan", "n_box_params"] == 7
    for law, row in evidence.iterrows():
        assert math.isfinite(row["log_z_box_double"]) and row["log_z_box_double"] < row["log_z"], law
        assert 0.0 <= row["posterior_mass_near_faces"] <= 1.0
    release = pd.read_csv(tmp_path / "release.csv")
    assert list(release.columns) == RELEASE_COLUMNS and len(release) == 2 * 3
    assert release["release_record_us"].between(0.5, 2.0).all()
    assert (release["n_runs"] > 0).all() and release["release_predicted_median_us"].between(0.5, 2.5).all()
    for name in ("evidence", "predictive_johnson-cook", "predictive_steinberg-guinan"):
        assert (tmp_path / "figures" / f"{name}.png").is_file(), name
