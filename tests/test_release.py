"""The release's arrival on a trace (shockcal.campaign.release) against synthetic traces whose release is known."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from shockcal.campaign.release import RELEASE_COLUMNS, predicted_releases_us, release_after_arrival_us, release_row
from shockcal.velocimetry.features import QUIET_ARRIVAL_FRACTION

DT_US = 1.0e-4
REPO = Path(__file__).resolve().parents[1]


def trace(arrival_us: float, release_us: float, plateau_m_s: float = 200.0, end_us: float = 3.0):
    """A noise-free free-surface trace: rest, an elastic ramp of 20 ns to 60 m/s at `arrival_us`, the plastic
    rise 0.3 us later to `plateau_m_s`, and at `release_us` a linear fall of 150 m/s over 0.2 us."""
    t = np.arange(0.0, end_us, DT_US)
    knots_t = [0.0, arrival_us, arrival_us + 0.02, arrival_us + 0.3, arrival_us + 0.35, release_us, release_us + 0.2,
               end_us]
    knots_v = [0.0, 0.0, 60.0, 60.0, plateau_m_s, plateau_m_s, plateau_m_s - 150.0, plateau_m_s - 150.0]
    return t, np.interp(t, knots_t, knots_v)


def expected_us(arrival_us, release_us, plateau_m_s=200.0, margin_m_s=20.0):
    """Closed form: the fall crosses plateau - margin at release + 0.2 margin / 150; the arrival detector fires
    where the elastic ramp crosses QUIET_ARRIVAL_FRACTION of the rise."""
    detected = arrival_us + 0.02 * QUIET_ARRIVAL_FRACTION * plateau_m_s / 60.0
    return release_us + 0.2 * margin_m_s / 150.0 - detected


@pytest.mark.parametrize("arrival, release", [(0.5, 1.6), (1.3, 2.05)])
def test_release_time_of_a_synthetic_trace(arrival, release):
    t, v = trace(arrival, release)
    found = release_after_arrival_us(t, v, t_plastic_us=arrival + 0.4, v_plastic_m_s=200.0)
    assert found == pytest.approx(expected_us(arrival, release), abs=2 * DT_US)
    wider = release_after_arrival_us(t, v, arrival + 0.4, 200.0, margin_m_s=50.0)
    assert wider == pytest.approx(expected_us(arrival, release, margin_m_s=50.0), abs=2 * DT_US)


def test_no_release_before_the_trace_ends_is_nan():
    t, v = trace(0.5, 2.95)                  # cut where the fall would start: still on the plateau
    assert math.isnan(release_after_arrival_us(t[t < 2.95], v[t < 2.95], 0.9, 200.0))


def test_predicted_releases_and_the_row():
    runs, feats = [], []
    for run, release in enumerate([1.5, 1.6, 1.7]):
        t, v = trace(0.5, release)
        runs.append({"run": run, "status": "ok", "t_us": t, "v_m_s": v})
        feats.append({"run": run, "status": "ok", "t_plastic": 0.9, "v_plastic": 200.0})
    runs.append({"run": 3, "status": "failed", "t_us": [], "v_m_s": []})
    feats.append({"run": 3, "status": "failed", "t_plastic": np.nan, "v_plastic": np.nan})
    predicted = predicted_releases_us(pd.DataFrame(runs), pd.DataFrame(feats))
    assert list(predicted.index) == [0, 1, 2]
    np.testing.assert_allclose(predicted, [expected_us(0.5, r) for r in (1.5, 1.6, 1.7)], atol=2 * DT_US)
    row = release_row("ptw", "104S", 1.2, [*predicted, math.nan])
    assert list(row) == RELEASE_COLUMNS
    assert row["release_predicted_median_us"] == pytest.approx(predicted[1])
    assert row["shift_us"] == pytest.approx(predicted[1] - 1.2)
    assert row["release_predicted_q05_us"] < row["release_predicted_median_us"] < row["release_predicted_q95_us"]
    assert (row["n_runs"], row["n_without_release"]) == (3, 1)


def _predictive_study(root, shots, releases_us):
    """A study's predictive run set as `model-predictions` reads it: per shot three synthetic runs (arrival 0.5 us,
    releases `releases_us`) in one chunk with their features, and the records' plastic plateaus (observed)."""
    from shockcal.io import write_table

    write_table(pd.DataFrame({"shot": list(shots), "t_plastic": [shots[s][0] for s in shots],
                              "v_plastic": [shots[s][1] for s in shots]}), root / "features" / "observed.parquet")
    for shot in shots:
        runs = [{"run": i, "status": "ok", "reason": "", **dict(zip(("t_us", "v_m_s"), trace(0.5, r, end_us=4.0)))}
                for i, r in enumerate(releases_us)]
        write_table(pd.DataFrame(runs), root / "predict" / "simulations" / shot / "chunk-0.parquet")
        write_table(pd.DataFrame({"run": range(len(releases_us)), "status": "ok", "t_plastic": 0.9, "v_plastic": 200.0}),
                    root / "predict" / "features" / f"{shot}.parquet")


def test_model_predictions_command(tmp_path, monkeypatch, capsys):
    """`shockcal model-predictions` on the paper's config (its three records) and two laws' synthetic runs: the
    table's predicted medians are the runs' known releases, shift_us their difference from the record's, and
    one figure page per law; a law without predictive runs is one line naming the file. The command runs in
    this process (`python -m shockcal` costs seconds of imports), from the repository like the Makefile's."""
    from shockcal.cli import main
    from shockcal.velocimetry.records import read_record

    monkeypatch.chdir(REPO)

    # the records' plastic plateaus as the extractor read them (results/quick/features/observed.parquet, 2026-11-26)
    shots = {"104S": (1.5667, 199.383), "105S": (2.6065, 358.816), "106S": (4.1035, 479.652)}
    _predictive_study(tmp_path / "jc", shots, [1.5, 1.6, 1.7])
    _predictive_study(tmp_path / "sg", shots, [1.7, 1.8, 1.9])
    out = tmp_path / "models" / "release.csv"
    code = main(["model-predictions", "--config", "config/config.yaml", "--model", f"jc={tmp_path / 'jc'}", "--model",
                 f"sg={tmp_path / 'sg'}", "--out", str(out), "--figures-dir", str(tmp_path / "models" / "figures")])
    assert code == 0, capsys.readouterr().err
    table = pd.read_csv(out)
    assert list(table.columns) == RELEASE_COLUMNS and len(table) == 6
    row = table.set_index(["model", "shot"]).loc[("steinberg-guinan", "104S")]
    assert row["release_predicted_median_us"] == pytest.approx(expected_us(0.5, 1.8), abs=2 * DT_US)
    t, v = read_record(REPO / "data" / "al5083" / "visar" / "Data_S104S.txt")
    assert row["release_record_us"] == pytest.approx(release_after_arrival_us(t, v, *shots["104S"]))
    assert 1.0 < row["release_record_us"] < 1.5          # the plateau of 104S lasts about 1.3 us (README Figure 11)
    assert row["shift_us"] == pytest.approx(row["release_predicted_median_us"] - row["release_record_us"])
    for law in ("johnson-cook", "steinberg-guinan"):
        assert (tmp_path / "models" / "figures" / f"predictive_{law}.png").is_file()
    capsys.readouterr()
    code = main(["model-predictions", "--config", "config/config.yaml", "--model", f"ptw={tmp_path / 'nowhere'}", "--out",
                 str(out)])
    err = capsys.readouterr().err
    assert code != 0 and "Traceback" not in err
    assert "--model ptw:" in err and "observed.parquet does not exist" in err
