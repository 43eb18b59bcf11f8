"""A sequential study's waves: their sizes, the bad wave configs refused in one line naming the key, the
stopping rule on constructed posterior summaries, and a later wave's design (the posterior thinned)."""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from shockcal.design.waves import maximin_subset, wave_design, widened
from shockcal.errors import ConfigError, InputError
from shockcal.inference.summaries import posterior_settled, quantile_shifts
from shockcal.study.config import prior_bounds, wave_sizes
from shockcal.study.validate import validate_config


def waves_config(paper_config, **waves):
    config = copy.deepcopy(paper_config)
    config["design"]["strategy"] = "waves"
    config["design"]["waves"] = waves
    return validate_config(config)


def test_wave_sizes_spend_the_budget(paper_config):
    assert wave_sizes(waves_config(paper_config, initial_runs=150, runs_per_wave=75, max_runs=300)) == [150, 75, 75]
    assert wave_sizes(waves_config(paper_config, initial_runs=150, runs_per_wave=75, max_runs=320)) == [150, 75, 75, 20]
    assert wave_sizes(waves_config(paper_config, initial_runs=150, runs_per_wave=75, max_runs=150)) == [150]
    assert wave_sizes(validate_config(copy.deepcopy(paper_config))) == [1000]     # the paper's design


@pytest.mark.parametrize("waves, message", [
    ({"runs_per_wave": 0}, r"^config: design\.waves\.runs_per_wave: 0 is less than the minimum of 1$"),
    ({"initial_runs": 0}, r"^config: design\.waves\.initial_runs: 0 is less than the minimum of 1$"),
    ({"initial_runs": 150, "max_runs": 100}, r"^config: design\.waves\.max_runs: 100 is below wave 0's "
                                              r"initial_runs \(150\)"),
    ({"criterion": "eivar"}, r"^config: design\.waves\.criterion: 'eivar' is not one of"),
    ({"widen": 0.5}, r"^config: design\.waves\.widen: 0\.5 is less than the minimum of 1"),
    ({"stop_box": 1.5}, r"^config: design\.waves\.stop_box: 1\.5 is greater than the maximum of 1"),
    ({"step_calibration": {"n_live": 10}},
     r"^config: design\.waves\.step_calibration\.n_live: 10 is less than the minimum of 50"),
])
def test_bad_wave_configs_are_refused_in_one_line(paper_config, waves, message):
    with pytest.raises(ConfigError, match=message) as refused:
        waves_config(paper_config, **waves)
    assert "\n" not in str(refused.value)


def test_a_design_file_and_waves_are_refused(paper_config, tmp_path):
    design = tmp_path / "design.csv"
    pd.DataFrame({"run": [0]}).to_csv(design, index=False)
    config = copy.deepcopy(paper_config)
    config["design"].update(strategy="waves", file=str(design))
    with pytest.raises(ConfigError, match=r"design\.file: a design file and design\.strategy: waves"):
        validate_config(config)


def summary(q: dict[str, tuple[float, float, float]], mcse: float) -> pd.DataFrame:
    return pd.DataFrame([{"parameter": name, "q05": a, "q50": b, "q95": c, "q05_mcse": mcse, "q50_mcse": mcse,
                          "q95_mcse": mcse} for name, (a, b, c) in q.items()])


def test_the_stopping_rule_counts_combined_monte_carlo_errors():
    before = summary({"A": (1.0, 2.0, 3.0), "n": (0.1, 0.5, 0.9)}, mcse=0.03)
    combined = np.hypot(0.03, 0.04)
    moved = summary({"A": (1.0, 2.0 + 2.9 * combined, 3.0), "n": (0.1, 0.5, 0.9 - 1.0 * combined)}, mcse=0.04)
    shifts = quantile_shifts(before, moved).set_index("parameter")
    np.testing.assert_allclose(shifts.loc["A"].to_numpy(), [0.0, 2.9, 0.0], atol=1e-12)
    np.testing.assert_allclose(shifts.loc["n"].to_numpy(), [0.0, 0.0, 1.0], atol=1e-12)
    assert posterior_settled(before, moved, threshold=3.0)
    assert not posterior_settled(before, moved, threshold=2.5)      # A's median moved 2.9 combined SE
    assert not posterior_settled(before, moved, threshold=0.0)      # 0: never stop early
    assert posterior_settled(before, before, threshold=3.0)         # the same posterior: nothing moved
    exact = summary({"A": (1.0, 2.0, 3.0)}, mcse=0.0)
    assert posterior_settled(exact, exact, 3.0)
    assert not posterior_settled(exact, summary({"A": (1.0, 2.1, 3.0)}, mcse=0.0), 3.0)   # a move with no error


def test_the_stopping_rule_lets_a_move_under_a_box_fraction_count_as_settled():
    before = summary({"A_MPa": (100.0, 300.0, 500.0), "lambda_y": (0.5, 1.0, 2.0)}, mcse=1.0)
    after = summary({"A_MPa": (100.0, 318.0, 500.0), "lambda_y": (0.5, 1.0, 2.0)}, mcse=1.0)   # 12.7 combined SE
    widths = {"A_MPa": 950.0}                                           # 18 MPa is 0.019 of it
    assert not posterior_settled(before, after, 3.0)
    assert posterior_settled(before, after, 3.0, widths, box_fraction=0.02)
    assert not posterior_settled(before, after, 3.0, widths, box_fraction=0.018)
    assert posterior_settled(before, after, 0.0, widths, box_fraction=0.02)      # the box fraction alone
    no_box = summary({"A_MPa": (100.0, 300.0, 500.0), "lambda_y": (0.5, 1.1, 2.0)}, mcse=0.01)
    assert not posterior_settled(summary({"A_MPa": (100.0, 300.0, 500.0), "lambda_y": (0.5, 1.0, 2.0)}, mcse=0.01),
                                 no_box, 3.0, widths, box_fraction=0.5)         # lambda_y has no box: SE alone


def test_maximin_picks_away_from_the_runs_so_far():
    candidates = np.array([[0.1, 0.1], [0.12, 0.1], [0.9, 0.9], [0.5, 0.5]])
    assert maximin_subset(candidates, np.array([[0.0, 0.0]]), 1).tolist() == [2]
    assert maximin_subset(candidates, np.array([[1.0, 1.0]]), 2).tolist() == [0, 3]
    with pytest.raises(InputError, match="3 runs asked of a pool of 2"):
        maximin_subset(candidates[:2], np.empty((0, 2)), 3)


def test_widening_keeps_the_pool_in_the_box():
    unit = np.random.default_rng(1).uniform(0.6, 1.0, size=(500, 3))
    wide = widened(unit, 2.0)
    assert wide.min() >= 0.0 and wide.max() <= 1.0
    assert np.all(wide.std(axis=0) > 1.5 * unit.std(axis=0))
    np.testing.assert_array_equal(widened(unit, 1.0), unit)


@pytest.fixture()
def posterior(paper_config):
    """A narrow 'posterior' of the paper's inputs: 3000 draws in the middle tenth of each input's range."""
    rng = np.random.default_rng(7)
    bounds = prior_bounds(paper_config)
    return pd.DataFrame({k: lo + (hi - lo) * rng.uniform(0.45, 0.55, 3000) for k, (lo, hi) in bounds.items()})


def test_a_wave_design_lies_in_the_posterior_with_new_run_ids(paper_config, posterior):
    bounds = prior_bounds(paper_config)
    existing = posterior.iloc[:5].assign(run=np.arange(5))[["run", *bounds]]
    design = wave_design(posterior, bounds, 20, first_run=5, seed=3, existing=existing, pool_size=1000)
    assert design.columns.tolist() == ["run", *bounds]
    assert design["run"].tolist() == list(range(5, 25))
    for name, (lo, hi) in bounds.items():
        scaled = (design[name] - lo) / (hi - lo)
        assert scaled.between(0.45, 0.55).all(), name
    assert not design[list(bounds)].duplicated().any()
    pd.testing.assert_frame_equal(design, wave_design(posterior, bounds, 20, 5, 3, existing, pool_size=1000))
    empty = wave_design(posterior, bounds, 0, first_run=5, seed=3)
    assert empty.empty and empty.columns.tolist() == ["run", *bounds]


def test_max_variance_thins_only_where_the_variance_is_largest(paper_config, posterior):
    bounds = prior_bounds(paper_config)
    variance = lambda pool: pool["A"].to_numpy()        # noqa: E731  largest at the pool's high A
    design = wave_design(posterior, bounds, 10, 0, 3, pool_size=1000, criterion="max_variance", variance=variance)
    pool_a = posterior["A"]
    assert (design["A"] >= pool_a.quantile(0.70)).all()
    with pytest.raises(InputError, match="max_variance criterion needs"):
        wave_design(posterior, bounds, 10, 0, 3, criterion="max_variance")


def test_wave_design_command_refuses_the_paper_design_in_one_line(tmp_path, monkeypatch, capsys):
    """The command runs in this process (`python -m shockcal` costs seconds of imports), from the repository."""
    from shockcal.cli import main

    monkeypatch.chdir(Path(__file__).resolve().parents[1])
    code = main(["wave-design", "--config", "config/config.yaml", "--wave", "1", "--posterior", "p.parquet",
                 "--previous-design", "d.parquet", "--runs", "r.parquet", "--out", str(tmp_path / "w.parquet")])
    stderr = capsys.readouterr().err
    assert code == 2
    assert len(stderr.strip().splitlines()) == 1
    assert stderr.strip().endswith("error: wave-design: design.strategy is 'lhs'; waves need 'waves'")


def test_a_stopped_wave_passes_through_simulate_and_features_with_no_runs(paper_config):
    from shockcal.simulators.builtin import simulate_design
    from shockcal.study.adapters import extractor_settings, hydro_inputs, shot_mapping
    from shockcal.velocimetry.feature_tables import check_failures, features_table

    bounds = prior_bounds(paper_config)
    empty = pd.DataFrame({"run": np.array([], dtype=np.int64), **{k: np.array([]) for k in bounds}})
    traces = simulate_design(empty, shot_mapping(paper_config, "104S"),
                             *hydro_inputs(paper_config, paper_config["shots"]["104S"]))
    assert traces.empty and {"run", "status", "reason", "t_us", "v_m_s"} <= set(traces.columns)
    with pytest.raises(InputError, match="no runs"):
        features_table(traces, extractor_settings(paper_config, "104S"), "chunk")
    features = features_table(traces, extractor_settings(paper_config, "104S"), "chunk", allow_empty=True)
    assert features.empty and "v_plastic" in features.columns
    check_failures(features, 0.05, "104S", allow_empty=True)
    with pytest.raises(InputError, match="no runs"):
        check_failures(features, 0.05, "104S")


def test_features_of_a_wave_with_runs_keep_their_values(paper_config):
    from shockcal.simulators.builtin import simulate_design
    from shockcal.study.adapters import extractor_settings, hydro_inputs, shot_mapping, study_design
    from shockcal.velocimetry.feature_tables import features_table

    design, _ = study_design(paper_config, n_runs=2)
    traces = simulate_design(design, shot_mapping(paper_config, "104S"),
                             *hydro_inputs(paper_config, paper_config["shots"]["104S"]))
    features = features_table(traces, extractor_settings(paper_config, "104S"), "chunk", allow_empty=True)
    assert features["v_plastic"].between(150, 260).all()


def test_an_archive_and_waves_are_refused(paper_config, tmp_path):
    config = copy.deepcopy(paper_config)
    config["design"]["strategy"] = "waves"
    config["simulator"] = {"kind": "archive", "archive": {"design": str(tmp_path / "design.csv"),
                                                          "features": {shot: str(tmp_path / f"{shot}.csv")
                                                                       for shot in config["shots"]}}}
    with pytest.raises(ConfigError, match=r"simulator\.kind: an archive holds only the runs it has") as refused:
        validate_config(config)
    assert "\n" not in str(refused.value)
