"""The `command` simulator with the example external code (examples/external_hydro): the builtin's traces bit
for bit, each fault of the misbehaving variant a failed run with its reason, the failure budget, and a
killed job resumed without rerunning its finished runs."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from shockcal.cli import main
from shockcal.design.tables import latin_hypercube
from shockcal.simulators.builtin import simulate_design
from shockcal.simulators.command import simulate_design_command
from shockcal.study.adapters import command_settings, hydro_inputs, shot_mapping
from shockcal.study.config import analysis_end_us, prior_bounds
from shockcal.study.validate import validate_config

REPO = Path(__file__).resolve().parents[1]
EXAMPLE = REPO / "examples" / "external_hydro"
RUN_HYDRO = f"{{python}} {EXAMPLE / 'run_hydro.py'} deck.txt trace.csv"
SHOT = "104S"


def command_config(config: dict, command: str = RUN_HYDRO, **changes) -> dict:
    """The paper's config on a coarse mesh, its runs made by `command` (the example's deck)."""
    config["hydro"].update(cell_size_um=20.0)
    section = {"templates": [str(EXAMPLE / "deck.txt")], "command": command, "timeout_s": 60,
               "output": {"kind": "trace", "file": "trace.csv", "time_column": "t_us", "velocity_column": "v_m_s"},
               **changes}
    config["simulator"] = {"kind": "command", "command": section}
    return validate_config(config)


def run_command(config: dict, design: pd.DataFrame, runs_dir: Path) -> pd.DataFrame:
    spec = config["shots"][SHOT]
    return simulate_design_command(design, shot_mapping(config, SHOT), *hydro_inputs(config, spec),
                                   command_settings(config), runs_dir, analysis_end_us(config, spec))


def design(config: dict, n_runs: int, seed: int = 5) -> pd.DataFrame:
    return latin_hypercube(prior_bounds(config), n_runs, seed=seed)


def alive(pid: int, wait_s: float = 5.0) -> bool:
    """Whether process `pid` still runs after up to `wait_s` (a killed orphan is a zombie until init reaps it)."""
    deadline = time.monotonic() + wait_s
    while time.monotonic() < deadline:
        try:
            state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
        except (FileNotFoundError, ProcessLookupError):
            return False
        if state in ("Z", "X"):
            return False
        time.sleep(0.1)
    return True


def test_the_example_code_gives_the_builtin_traces_bit_for_bit(paper_config, tmp_path):
    config = command_config(paper_config)
    rows = design(config, 1)
    table = run_command(config, rows, tmp_path)
    builtin = simulate_design(rows, shot_mapping(config, SHOT), *hydro_inputs(config, config["shots"][SHOT]))
    assert list(table.columns) == list(builtin.columns)
    assert table["status"].tolist() == ["ok"]
    for ours, theirs in zip(table.itertuples(), builtin.itertuples()):
        assert np.array_equal(ours.t_us, theirs.t_us) and np.array_equal(ours.v_m_s, theirs.v_m_s)
        assert ours.impact_velocity_m_s == theirs.impact_velocity_m_s
    assert (tmp_path / SHOT / str(rows["run"].iloc[0]) / "deck.txt").is_file()


@pytest.mark.parametrize("fault, reason", [
    ("exit", r"nonzero exit: exit code 3; stderr ends: run_hydro: run 0: injected failure"),
    ("half", r"output truncated: trace\.csv: the trace stops at .* us, before the analysis window's latest end"),
    ("cm-us", r"output units: trace\.csv: peak velocity 0\.0\d+ m/s is outside 0\.85-1\.05 x the run's impact velocity "
              r"\d+\.?\d* m/s .*; it fits if the velocities are in cm/us"),
])
def test_each_fault_is_a_failed_run_with_its_reason(paper_config, tmp_path, fault, reason):
    config = command_config(paper_config, f"{RUN_HYDRO} --fault {fault}")
    table = run_command(config, design(config, 1), tmp_path)
    assert table["status"].tolist() == ["failed"]
    assert pd.Series(table["reason"]).str.match(reason).all(), table["reason"].iloc[0]
    assert (tmp_path / SHOT / "0" / "stderr.txt").is_file()
    assert json.loads((tmp_path / SHOT / "0" / "done.json").read_text())["status"] == "failed"


def test_a_hang_is_killed_with_its_process_group_at_the_timeout(paper_config, tmp_path):
    """The command starts a child that would outlive it (`sleep &`): the timeout ends both."""
    config = command_config(paper_config, "sleep 60 & echo $! > child.pid; " + f"{RUN_HYDRO} --fault hang",
                            timeout_s=1, retries=1)
    start = time.perf_counter()
    table = run_command(config, design(config, 1), tmp_path)
    assert time.perf_counter() - start < 20
    assert table["reason"].iloc[0] == ("timeout: no exit within 1 s; its process group was killed (attempt 2 of 2)")
    folder = tmp_path / SHOT / "0"
    assert (folder / "stderr.attempt-1.txt").is_file()
    assert not alive(int((folder / "child.pid").read_text()))


def test_below_the_budget_the_rest_complete_above_it_one_line(paper_config, tmp_path, capsys, monkeypatch):
    """Five runs, the example exiting at random (seeded) on 40% of them: two fail here."""
    config = command_config(paper_config, f"{RUN_HYDRO} --fault exit --fault-fraction 0.4 --seed 2")
    table = run_command(config, design(config, 5), tmp_path)
    failed = table["status"].eq("failed")
    assert failed.sum() == 2 and table.loc[~failed, "t_us"].map(len).gt(0).all()
    chunk = tmp_path / "chunk.parquet"
    table.to_parquet(chunk)
    monkeypatch.chdir(REPO)          # the config's record paths are relative to the repository
    for fraction, code in ((0.5, 0), (0.2, 2)):
        config["simulate"]["max_failed_fraction"] = fraction
        path = tmp_path / "config.yaml"
        path.write_text(yaml.safe_dump(config))
        out = tmp_path / f"features-{fraction}.parquet"
        assert main(["features", "--config", str(path), "--shot", SHOT, "--traces", str(chunk), "--out", str(out)]) == code
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert err.startswith("shockcal features: error: shot 104S: 2 of 5 runs failed, more than the allowed 20% "
                          "(simulate.max_failed_fraction); the commonest reason, 2 runs: nonzero exit (e.g. run ")
    assert pd.read_parquet(tmp_path / "features-0.5.parquet")["status"].eq("ok").sum() == 3


def test_a_killed_job_resumes_without_rerunning_finished_runs(paper_config, tmp_path, monkeypatch):
    """Run 1 hangs while $HANG is set: the job is killed (SIGTERM, as snakemake or scancel do) once run 0 is
    done; the rerun reads run 0 back from its folder, after an unrelated change (the timeout) too."""
    hang = 'if [ {run} = 1 ] && [ -n "$HANG" ]; then echo $$ > hung.pid; sleep 60; fi; '
    config = command_config(paper_config, hang + RUN_HYDRO)
    path = tmp_path / "config.yaml"
    path.write_text(yaml.safe_dump(config))
    design(config, 2).to_csv(tmp_path / "design.csv", index=False)
    args = ["simulate", "--config", str(path), "--shot", SHOT, "--design", str(tmp_path / "design.csv"),
            "--runs-dir", str(tmp_path / "runs"), "--out", str(tmp_path / "chunk.parquet")]
    job = subprocess.Popen([sys.executable, "-m", "shockcal", *args], env={**os.environ, "HANG": "1"}, cwd=REPO,
                           stderr=subprocess.DEVNULL)
    pid_file = tmp_path / "runs" / SHOT / "1" / "hung.pid"
    deadline = time.monotonic() + 120
    while not pid_file.is_file() and job.poll() is None and time.monotonic() < deadline:
        time.sleep(0.2)
    time.sleep(0.2)
    job.send_signal(signal.SIGTERM)
    assert job.wait(timeout=30) != 0 and not (tmp_path / "chunk.parquet").exists()
    assert not alive(int(pid_file.read_text()))              # the hung command's group went with the job
    done = tmp_path / "runs" / SHOT / "0" / "done.json"
    first = done.stat().st_mtime_ns
    assert not (tmp_path / "runs" / SHOT / "1" / "done.json").exists()
    config["simulator"]["command"]["timeout_s"] = 90
    path.write_text(yaml.safe_dump(config))
    monkeypatch.chdir(REPO)
    assert main(args) == 0
    assert done.stat().st_mtime_ns == first
    assert pd.read_parquet(tmp_path / "chunk.parquet")["status"].tolist() == ["ok", "ok"]


@pytest.mark.parametrize("value, status, reason", [
    (None, "ok", ""),
    ("nan", "failed", "output non-finite: features.csv: v_jumpoff, v_elastic, v_plastic"),
    ("0.02", "failed", "output units: features.csv: the largest velocity feature"),
])
def test_a_code_that_writes_its_own_features(paper_config, tmp_path, value, status, reason):
    """`output.kind: features`: the row's features reach the features table as they are."""
    from shockcal.velocimetry.columns import COLUMNS
    from shockcal.velocimetry.feature_tables import features_table
    from shockcal.velocimetry.features import ExtractorSettings

    features = dict(paper_config["observed"]["features"][SHOT])
    if value is not None:
        features.update({name: value for name in features if name.startswith("v_")})
    header, row = ",".join(features), ",".join(str(v) for v in features.values())
    config = command_config(paper_config, f"printf '{header}\\n{row}\\n' > features.csv",
                            output={"kind": "features", "file": "features.csv"})
    table = features_table(run_command(config, design(config, 1), tmp_path), ExtractorSettings())
    assert table["status"].tolist() == [status] and table["reason"].iloc[0].startswith(reason)
    if status == "ok":
        assert table[COLUMNS].iloc[0].tolist() == [features[c] for c in COLUMNS]
