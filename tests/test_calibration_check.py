"""Calibration against a shot-aware stand-in emulator: likelihood formula, synthetic-truth coverage, CLI."""

from __future__ import annotations

import copy
import json
import re
import warnings

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from shockcal.emulator.error_model import ErrorModel
from shockcal.errors import InputError
from shockcal.inference.calibration import calibrate
from shockcal.inference.coverage import (
    HydroTruths,
    coverage_by_fifth,
    coverage_table,
    hpd_mass,
    joint_coverage,
    paired_coverage,
    synthetic_truth,
)
from shockcal.inference.problem import Problem, log_density
from shockcal.study.adapters import calibration_settings

FEATURES = ["v_elastic", "v_plastic", "v_slope1", "v_slope2"]
SHOT_INPUTS = {"104S": ["A", "B", "C", "n", "m", "V1", "G1"],
               "105S": ["A", "B", "C", "n", "m", "V2", "G1", "Delta2"],
               "toy": ["A", "n"]}


class ShotEmulator:
    """Same interface as shockcal.emulator.study_emulator.Emulator: features linear in the box-scaled inputs."""

    feature_names = FEATURES

    def __init__(self, config, shots=("104S",), emulator_sd=0.5):
        self.shots = list(shots)
        self.bounds = {k: (v["min"], v["max"]) for k, v in config["inputs"].items()}
        rng = np.random.default_rng(7)
        self.base = {s: np.array([70.0, 200.0, 80.0, 190.0]) * (1 + 0.5 * i) for i, s in enumerate(self.shots)}
        self.gain = {s: {k: rng.uniform(-8, 8, 4) for k in SHOT_INPUTS[s]} for s in self.shots}
        self.sd = emulator_sd

    def required_inputs(self, shots):
        missing = [s for s in shots if s not in self.shots]
        if missing:
            raise InputError(f"the emulator has no shot {missing}")
        needed = {k for s in shots for k in SHOT_INPUTS[s]}
        return [k for k in self.bounds if k in needed]

    def input_bounds(self, names):
        return np.array([self.bounds[k][0] for k in names]), np.array([self.bounds[k][1] for k in names])

    def check_study(self, shot_inputs, bounds, label="the emulator"):
        """Made from the config's own box and mappings: it always fits its study."""

    def predict(self, inputs, shots):
        n = len(np.atleast_1d(inputs[self.required_inputs(shots)[0]]))
        blocks = []
        for s in shots:
            m = np.tile(self.base[s], (n, 1))
            for k, g in self.gain[s].items():
                lo, hi = self.bounds[k]
                m = m + ((np.asarray(inputs[k]) - lo) / (hi - lo) - 0.5)[:, None] * g
            blocks.append(m)
        f = 4 * len(shots)
        return np.hstack(blocks), np.tile(self.sd**2 * np.eye(f), (n, 1, 1))

    def error_groups(self, shots):
        return [(np.arange(4 * len(shots)), ErrorModel())]


def observed_at(emulator, shots, theta: dict) -> pd.DataFrame:
    mean, _ = emulator.predict({k: np.array([v]) for k, v in theta.items()}, shots)
    return pd.DataFrame(mean.reshape(len(shots), 4), columns=FEATURES).assign(shot=shots, source="test")


def mid_box(emulator, shots) -> dict:
    names = emulator.required_inputs(shots)
    return dict(zip(names, np.mean(emulator.input_bounds(names), axis=0)))


def _settings(config, n_live=None, n_eff=None):
    """The config's calibration settings, the sampler's live points and ESS replaced when given."""
    settings = calibration_settings(config, ["toy"])
    return settings.with_sampler(n_live=n_live or settings.sampler.n_live, n_eff=n_eff or settings.sampler.n_eff)


@pytest.fixture
def small_config(paper_config):
    paper_config["calibration"].update(n_live=200, n_eff=500, draws=2000)
    return paper_config


@pytest.fixture(scope="module")
def three_toy_trials(paper_config_readonly):
    """Three synthetic-truth trials on the toy emulator, seed 4, run once for the tests that read them."""
    config = copy.deepcopy(paper_config_readonly)
    config["calibration"].update(n_live=200, n_eff=500, draws=2000)
    emu = ShotEmulator(config, shots=["toy"], emulator_sd=0.3)
    return emu, config, synthetic_truth(emu, ["toy"], _settings(config, 100, 300), trials=3, seed=4)


def test_log_posterior_matches_the_gaussian_formula(small_config):
    emu = ShotEmulator(small_config)
    names = emu.required_inputs(["104S"])
    lo, hi = emu.input_bounds(names)
    theta = (lo + hi) / 2
    problem = Problem.for_shots(emu, ["104S"], observed_at(emu, ["104S"], dict(zip(names, theta * 1.01))), 0.01)
    lam = 2.0
    mean, cov = emu.predict(dict(zip(names, theta[:, None])), ["104S"])
    total = cov[0] + np.diag((0.01 * problem.observed) ** 2) / lam
    r = problem.observed - mean[0]
    # Gaussian log density + log Gamma(5, 5) density of lambda (up to its constant) + log Jacobian of log lambda
    log_like = -0.5 * r @ np.linalg.solve(total, r) - 0.5 * np.linalg.slogdet(2 * np.pi * total)[1]
    expected = log_like + 5 * np.log(lam) - 5 * lam
    assert problem.log_likelihood(np.append(theta, lam)[None])[0] == pytest.approx(log_like, rel=1e-10)
    assert problem.log_posterior(np.append(theta, np.log(lam))[None])[0] == pytest.approx(expected, rel=1e-10)
    assert problem.log_posterior(np.append(hi * 1.1, 0.0)[None])[0] == -np.inf


def test_shot_without_emulator_is_rejected(small_config):
    emu = ShotEmulator(small_config, shots=["104S"])
    obs = pd.DataFrame([{"shot": "106S", **dict.fromkeys(FEATURES, 100.0)}])
    with pytest.raises(InputError, match="no shot"):
        calibrate(emu, ["106S"], obs, calibration_settings(small_config, ["106S"]))


def test_synthetic_truth_table_and_binomial_band(three_toy_trials):
    _, _, trials = three_toy_trials
    assert list(trials.columns) == ["trial", "run", "parameter", "truth", "q05", "q95", "sd", "inside", "ess",
                                    "truth_hpd_mass", "status", "reason"]
    assert (trials["status"] == "ok").all() and (trials["reason"] == "").all() and trials["run"].isna().all()
    # a 90% interval spans about 3.3 sd for a Gaussian posterior: a loose bracket of the sd against it
    assert ((trials["q95"] - trials["q05"]) / trials["sd"]).between(2.0, 4.5).all()
    assert len(trials) == 3 * 3 and (trials["q05"] < trials["q95"]).all() and (trials["ess"] >= 300).all()
    per_trial = trials.groupby("trial")["truth_hpd_mass"]
    assert (per_trial.nunique() == 1).all() and trials["truth_hpd_mass"].between(0.0, 1.0).all()
    table = coverage_table(pd.concat([trials] * 34, ignore_index=True).assign(trial=np.repeat(np.arange(102), 3)))
    # 102 trials, nominal 0.9: the central 95% binomial band is 0.843-0.951
    assert table["band_low"].iloc[0] == pytest.approx(86 / 102) and table["band_high"].iloc[0] == pytest.approx(97 / 102)


def test_a_discrepancy_leaves_the_joint_mass_empty_and_keeps_the_intervals(paper_config):
    """With `calibration.discrepancy` the truth has no discrepancy parameters to place in the posterior's joint
    density: the trial's truth_hpd_mass is empty (the joint check is skipped), its per-parameter intervals are
    there as without one."""
    emu = ShotEmulator(paper_config, shots=["toy"], emulator_sd=0.3)
    # the sampler's least settings: what is checked (an empty joint mass, ordered intervals, the parameters)
    # does not depend on the run's size
    settings = _settings(paper_config, 50, 100).replace(discrepancy={"kind": "feature_kind"})
    trials = synthetic_truth(emu, ["toy"], settings, trials=1, seed=4)
    assert (trials["status"] == "ok").all() and trials["truth_hpd_mass"].isna().all()
    assert (trials["q05"] < trials["q95"]).all() and set(trials["parameter"]) == {*emu.required_inputs(["toy"]), "lambda_y"}


def test_failed_trials_are_recorded_with_their_reason_not_the_end_of_the_batch(paper_config):
    emu = ShotEmulator(paper_config, shots=["toy"], emulator_sd=0.3)
    # max_evaluations 1000 is the least the config takes; 500 live points spend them on one or two bounds (100 took
    # ten networks per trial), and no run of 1000 evaluations reaches an ESS of 3000 whatever its live points
    starved = _settings(paper_config, 500, 3000).with_sampler(max_evaluations=1000)
    trials = synthetic_truth(emu, ["toy"], starved, trials=2, seed=4)
    assert len(trials) == 2 * 3 and sorted(trials["trial"].unique()) == [0, 1]
    assert (trials["status"] == "failed").all() and trials["reason"].str.contains("max_evaluations").all()
    assert trials[["q05", "q95", "ess", "truth_hpd_mass"]].isna().all().all()
    with pytest.raises(InputError, match="no synthetic-truth trial finished: 2 failed, the first with: nautilus"):
        coverage_table(trials)


def test_coverage_leaves_failed_trials_out_and_counts_them(three_toy_trials):
    _, _, trials = three_toy_trials
    marked = trials.copy()
    second = marked["trial"] == 1
    marked.loc[second, ["q05", "q95", "inside", "ess", "truth_hpd_mass"]] = None
    marked.loc[second, ["status", "reason"]] = ["failed", "stand-in failure"]
    table = coverage_table(marked).set_index("parameter")
    assert (table["trials"] == 2).all() and (table["failed_trials"] == 1).all()
    finished = trials[~second].groupby("parameter")["inside"].mean()
    np.testing.assert_allclose(table["coverage90"], finished[table.index].to_numpy(dtype=float))
    assert joint_coverage(marked)["trials"] == 2
    older = trials.drop(columns=["status", "reason"]).assign(trial=trials["trial"] + 10)   # batches from before
    assert (coverage_table(pd.concat([marked, older], ignore_index=True))["trials"] == 5).all()


def test_coverage_by_fifth_finds_the_misses_at_low_truths():
    """100 trials, the truths of n shuffled: the intervals miss every truth below 0.15 (the lowest 10) and
    hold the rest; A's hold everywhere but at trials 0-9, spread over its truths. Per fifth of the truths:
    n's lowest fifth 0.50, its others 1.00; A's misses wherever its truths of trials 0-9 fall. A failed
    trial is left out."""
    rng = np.random.default_rng(8)
    n_truth = rng.permutation(np.linspace(0.0, 1.5, 100))
    a_truth = rng.uniform(size=100)
    rows = pd.concat([pd.DataFrame({"trial": np.arange(100), "parameter": "n", "truth": n_truth,
                                    "inside": n_truth >= 0.15, "status": "ok"}),
                      pd.DataFrame({"trial": np.arange(100), "parameter": "A", "truth": a_truth,
                                    "inside": np.arange(100) >= 10, "status": "ok"})], ignore_index=True)
    failed = pd.DataFrame({"trial": [100], "parameter": ["n"], "truth": [0.0], "inside": [None], "status": ["failed"]})
    table = coverage_by_fifth(pd.concat([rows, failed], ignore_index=True))
    assert list(table.index) == ["n", "A"] and list(table.columns) == ["1/5", "2/5", "3/5", "4/5", "5/5"]
    np.testing.assert_allclose(table.loc["n"], [0.5, 1.0, 1.0, 1.0, 1.0])
    fifth_of_a = (pd.Series(a_truth).rank(method="first").to_numpy() - 1) * 5 // 100
    misses = np.bincount(fifth_of_a[:10].astype(int), minlength=5)
    np.testing.assert_allclose(table.loc["A"], 1.0 - misses / 20)
    with warnings.catch_warnings():                  # four trials: the fifth fifth is empty, NaN and no warning
        warnings.simplefilter("error")
        few = coverage_by_fifth(rows[rows["trial"] < 4])
    assert few.loc["n"].isna().tolist() == [False] * 4 + [True]


def test_hpd_mass_of_a_known_gaussian():
    # 200,000 draws of a 2-d standard normal; a truth on the circle holding 90% of the mass
    rng = np.random.default_rng(3)
    draws = rng.normal(size=(200_000, 2))
    radius_sq = stats.chi2(2).ppf(0.9)
    mass = hpd_mass(-0.5 * np.sum(draws**2, axis=1), -0.5 * radius_sq)
    assert mass == pytest.approx(0.9, abs=0.003)
    assert hpd_mass(-0.5 * np.sum(draws**2, axis=1), 0.0) == 0.0          # the mode: nothing is denser


def test_log_density_adds_the_gamma_prior_of_lambda_y():
    assert log_density(-3.0, 1.0) == pytest.approx(-3.0 + stats.gamma(5, scale=0.2).logpdf(1.0))


def test_joint_coverage_of_uniform_and_of_too_narrow_masses():
    # calibrated: the masses are uniform; too narrow posteriors put the truths in the outer shells
    rng = np.random.default_rng(5)
    uniform = pd.DataFrame({"trial": np.repeat(np.arange(400), 2), "truth_hpd_mass": np.repeat(rng.uniform(size=400), 2)})
    good = joint_coverage(uniform)
    assert good["trials"] == 400 and good["band_low"] <= good["coverage90"] <= good["band_high"]
    assert good["uniform_ks_p"] > 0.01
    narrow = uniform.assign(truth_hpd_mass=uniform["truth_hpd_mass"] ** 0.5)
    bad = joint_coverage(narrow)
    assert bad["coverage90"] < bad["band_low"] and bad["uniform_ks_p"] < 1e-6


def _check_rows(inside_a, inside_n, masses, runs):
    """A per-trial table of two parameters (A, n) with the given inside flags, truth masses and runs."""
    rows = [{"trial": t, "run": run, "parameter": name, "truth": 0.5, "q05": 0.0, "q95": 1.0 if flag else 0.1,
             "inside": flag, "ess": 900.0, "truth_hpd_mass": mass, "status": "ok", "reason": ""}
            for t, (a, n, mass, run) in enumerate(zip(inside_a, inside_n, masses, runs))
            for name, flag in (("A", a), ("n", n))]
    return pd.DataFrame(rows)


def test_paired_coverage_counts_the_trials_one_check_alone_covers():
    """Six trials covered by the hydrocode check alone and none by the reference alone give McNemar's
    exact p = 2 / 2^6; identical checks give 1; the joint row reads the truth masses; checks on other
    truths, or with no trial in common, are refused."""
    n = 20
    here = _check_rows([True] * n, [True] * 10 + [False] * 10, np.linspace(0.0, 0.95, n), range(n))
    there = _check_rows([True] * 14 + [False] * 6, [True] * 10 + [False] * 10, np.linspace(0.0, 0.95, n)[::-1],
                        range(n))
    table = paired_coverage(here, there).set_index("parameter")
    assert table.loc["A", ["only_here", "only_reference"]].tolist() == [6, 0]
    assert table.loc["A", "mcnemar_p"] == pytest.approx(2 / 2**6)
    assert table.loc["A", "coverage90"] == 1.0 and table.loc["A", "reference_coverage90"] == pytest.approx(0.7)
    assert table.loc["n", "mcnemar_p"] == 1.0 and table.loc["n", "only_here"] == 0
    masses = np.linspace(0.0, 0.95, n)
    assert table.loc["joint", "coverage90"] == np.mean(masses <= 0.9)
    assert table.loc["joint", "only_here"] == np.sum((masses <= 0.9) & (masses[::-1] > 0.9))
    with pytest.raises(InputError, match="trial 0 has truth run 0 in one check and 5"):
        paired_coverage(here, there.assign(run=there["run"] + 5))
    with pytest.raises(InputError, match="share no finished trial"):
        paired_coverage(here, there.assign(status="failed"))


@pytest.mark.slow
def test_synthetic_truth_in_batches_equals_one_run(three_toy_trials):
    # each trial has its own random stream: the workflow's batches of trials are independent jobs
    emu, config, whole = three_toy_trials
    batches = [synthetic_truth(emu, ["toy"], _settings(config, 100, 300), trials=range(*r), seed=4)
               for r in [(2, 3), (0, 2)]]
    merged = pd.concat(batches).sort_values("trial", kind="stable").reset_index(drop=True)
    pd.testing.assert_frame_equal(merged, whole)
    assert whole["trial"].tolist() == [0, 0, 0, 1, 1, 1, 2, 2, 2]


def test_hydro_truth_needs_a_usable_run_per_trial(small_config):
    emu = ShotEmulator(small_config, shots=["toy"], emulator_sd=0.3)
    truths, _ = _toy_hydro_truths(emu, small_config, n_runs=5)     # 3 usable runs
    with pytest.raises(InputError, match="trial 3 needs hydrocode run number 4, but only 3"):
        synthetic_truth(emu, ["toy"], _settings(small_config), trials=range(2, 4), seed=4, truths=truths)


def test_coverage_command_merges_batches_and_rejects_a_repeated_trial(tmp_path, capsys):
    from shockcal.cli import main
    from shockcal.io import read_table

    def batch(trials, name):
        rows = [{"trial": t, "parameter": p, "truth": 0.5, "q05": 0.0, "q95": 1.0 if t % 5 else 0.1,
                 "inside": bool(t % 5), "ess": 900.0} for t in trials for p in ("A", "lambda_y")]
        path = tmp_path / name
        pd.DataFrame(rows).to_parquet(path)
        return str(path)

    first, second = batch(range(10, 20), "b1.parquet"), batch(range(10), "b0.parquet")
    assert main(["coverage", "--trials", first, second, "--out", str(tmp_path / "all.parquet")]) == 0
    merged = read_table(tmp_path / "all.parquet")
    assert merged["trial"].tolist() == sorted(merged["trial"].tolist()) and merged["trial"].nunique() == 20
    table = coverage_table(merged)
    assert table["coverage90"].tolist() == [0.8, 0.8]
    # the misses: q95 = 0.1 below the truth 0.5, so all above q95, none below q05
    assert table["above_q95"].tolist() == [0.2, 0.2] and table["below_q05"].tolist() == [0.0, 0.0]
    again = batch(range(5, 8), "b2.parquet")
    assert main(["coverage", "--trials", second, again, "--out", str(tmp_path / "bad.parquet")]) == 2
    assert "trial 5 is in more than one" in capsys.readouterr().err
    assert not (tmp_path / "bad.parquet").exists()
    assert main(["coverage", "--trials", first, "--out", str(tmp_path / "one.parquet"), "--against", second]) == 2
    assert "the check has no truth runs" in capsys.readouterr().err


def test_coverage_command_compares_two_checks_on_the_same_truths(tmp_path, caplog):
    from shockcal.cli import main

    paths = []
    for name, flags in (("here", [True] * 8 + [False] * 2), ("there", [True] * 4 + [False] * 6)):
        paths.append(str(tmp_path / f"{name}.parquet"))
        _check_rows(flags, flags, np.linspace(0.0, 0.95, 10), range(10)).to_parquet(paths[-1])
    with caplog.at_level("INFO", logger="shockcal.calibrate"):
        assert main(["coverage", "--trials", paths[0], "--out", str(tmp_path / "all.parquet"), "--against",
                     paths[1]]) == 0
    assert re.search(r"\n\s+A\s+10\s+0\.800\s+0\.400\s+4\s+0\s+0\.125", caplog.text), caplog.text


@pytest.mark.slow
def test_synthetic_truth_coverage_is_near_nominal(small_config):
    # A two-input shot and 40 trials (about 5 min: nautilus costs a few seconds per run even on a toy).
    emu = ShotEmulator(small_config, shots=["toy"], emulator_sd=0.3)
    trials = synthetic_truth(emu, ["toy"], _settings(small_config, 100, 300), trials=40, seed=4)
    table = coverage_table(trials)
    assert (table["trials"] == 40).all(), table
    assert table["within_band"].all() and table["band_low"].iloc[0] == pytest.approx(0.8), table
    assert 0.84 <= trials["inside"].mean() <= 0.96, table


@pytest.mark.slow
def test_synthetic_truth_coverage_hundred_trials_within_the_binomial_band(small_config):
    emu = ShotEmulator(small_config, shots=["toy"], emulator_sd=0.3)
    table = coverage_table(synthetic_truth(emu, ["toy"], _settings(small_config, 100, 300), trials=100, seed=4))
    assert table["within_band"].all() and table["band_low"].iloc[0] == pytest.approx(0.84), table


def _toy_hydro_truths(emu, config, n_runs=60):
    """Stand-in hydrocode runs: uniform theta, features = the emulator's mean plus its own error
    (sd 0.3 m/s, which the emulator's covariance reports); run 0 failed, run 1 non-positive."""
    rng = np.random.default_rng(11)
    lower, upper = emu.input_bounds(["A", "n"])
    theta = rng.uniform(lower, upper, size=(n_runs, 2))
    design = pd.DataFrame({"run": np.arange(n_runs), "A": theta[:, 0], "n": theta[:, 1], "m": 1.0})
    mean, _ = emu.predict({"A": theta[:, 0], "n": theta[:, 1]}, ["toy"])
    features = pd.DataFrame(mean + emu.sd * rng.normal(size=mean.shape), columns=FEATURES)
    features.insert(0, "run", np.arange(n_runs))
    features.insert(1, "status", ["failed"] + ["ok"] * (n_runs - 1))
    features.loc[1, "v_slope1"] = -3.0
    return HydroTruths(design, {"toy": features}), theta


def test_hydro_truths_skip_failed_and_non_positive_runs(small_config):
    emu = ShotEmulator(small_config, shots=["toy"], emulator_sd=0.3)
    truths, theta = _toy_hydro_truths(emu, small_config)
    draws = truths.table(["A", "n"], ["toy"])
    assert len(draws) == 58
    np.testing.assert_array_equal(draws[0][0], theta[2])
    assert draws[0][1].shape == (4,)


@pytest.mark.slow
def test_design_truths_without_features_draw_them_from_the_emulator(small_config):
    """A truth design alone: each trial's truth is its row's inputs and lambda_y, its features the
    emulator's draw there (so its check differs from the hydrocode truths' only by the emulator)."""
    emu = ShotEmulator(small_config, shots=["toy"], emulator_sd=0.3)
    truths, theta = _toy_hydro_truths(emu, small_config, n_runs=6)
    design = truths.design.assign(lambda_y=np.linspace(0.5, 1.5, 6)).sample(frac=1.0, random_state=1)
    alone = HydroTruths(design, None)
    rows = alone.table(["A", "n"], ["toy"])
    assert [row.run for row in rows] == list(range(6)) and all(row.features is None for row in rows)
    np.testing.assert_array_equal(rows[4].theta, theta[4])
    trials = synthetic_truth(emu, ["toy"], _settings(small_config, 100, 300), trials=range(2, 4), seed=4, truths=alone)
    table = trials.set_index(["trial", "parameter"])
    assert (trials["status"] == "ok").all() and list(trials["run"].unique()) == [2, 3]
    assert table.loc[(3, "A"), "truth"] == theta[3, 0] and table.loc[(3, "lambda_y"), "truth"] == pytest.approx(1.1)
    with pytest.raises(InputError, match="truth design"):
        HydroTruths(design.drop(columns="n"), None).table(["A", "n"], ["toy"])


@pytest.mark.slow
def test_hydro_truth_coverage_is_near_nominal(small_config):
    emu = ShotEmulator(small_config, shots=["toy"], emulator_sd=0.3)
    truths, _ = _toy_hydro_truths(emu, small_config)
    trials = synthetic_truth(emu, ["toy"], _settings(small_config, 100, 300), trials=40, seed=5, truths=truths)
    assert trials["trial"].nunique() == 40
    assert 0.84 <= trials["inside"].mean() <= 0.96, coverage_table(trials)


@pytest.mark.slow
def test_synthetic_truth_coverage_eight_inputs(small_config):
    emu = ShotEmulator(small_config, shots=["105S"], emulator_sd=0.3)
    trials = synthetic_truth(emu, ["105S"], _settings(small_config, 500, 1000), trials=100, seed=4)
    table = coverage_table(trials)
    print(table.to_string())
    assert table["within_band"].all(), table


def test_cli_writes_samples_and_summary_and_rejects_other_emulator_versions(small_config, tmp_path, monkeypatch,
                                                                             capsys):
    import yaml

    from shockcal.cli import main
    from shockcal.io import read_table_metadata

    # the sampler's least settings: what is checked (the files, their units and names, quantiles inside the box,
    # the refusals) does not depend on the run's size
    small_config["calibration"].update(n_live=50, n_eff=100, draws=1000)
    config_path = tmp_path / "config.yaml"
    config_path.write_text(yaml.safe_dump(small_config))
    emu = ShotEmulator(small_config)
    observed_at(emu, ["104S"], mid_box(emu, ["104S"])).to_csv(tmp_path / "obs.csv", index=False)
    monkeypatch.setattr("shockcal.emulator.study_emulator.Emulator.load", classmethod(lambda cls, path: emu))
    out = tmp_path / "post" / "104S.parquet"
    args = ["calibrate", "--config", str(config_path), "--emulator", "E", "--shots", "104S",
            "--observed", str(tmp_path / "obs.csv"), "--out", str(out)]
    assert main(args) == 0
    meta = read_table_metadata(out)
    assert meta["units"]["V1"] == "cm/us" and meta["user_units"]["V1"] == "m/s" and meta["shots"] == ["104S"]
    assert meta["user_units"]["G1"] == "GPa" and meta["user_units"]["A"] == "MPa"
    summary = pd.read_parquet(tmp_path / "post" / "104S_summary.parquet").set_index("parameter")
    user_names = {"A": "A_MPa", "B": "B_MPa", "V1": "V1_m_s", "G1": "G1_GPa"}
    assert summary.index.tolist() == [*(user_names.get(k, k) for k in emu.required_inputs(["104S"])), "lambda_y"]
    box = small_config["inputs"]["V1"]                      # the velocity's quantiles in m/s, inside its box
    assert 1e4 * box["min"] <= summary.loc["V1_m_s", "q05"] <= summary.loc["V1_m_s", "q95"] <= 1e4 * box["max"]

    for option, value, message in [("--n-live", "10", "--n-live: SamplerSettings.n_live 10: Input should be greater "
                                                       "than or equal to 50"),
                                   ("--n-eff", "20", "--n-eff: SamplerSettings.n_eff 20: Input should be greater than "
                                                     "or equal to 100")]:
        assert main([*args, option, value]) == 2                          # refused before any sampling, in one line
        err = capsys.readouterr().err.strip()
        assert message in err and "\n" not in err, err

    monkeypatch.undo()
    old = tmp_path / "old_emulator"
    old.mkdir()
    (old / "emulator.json").write_text(json.dumps({"format": "shockcal-emulator", "version": 0}))
    (old / "emulator.npz").write_bytes(b"")
    assert main([*args[:4], str(old), *args[5:]]) == 2
    assert "version" in capsys.readouterr().err


@pytest.mark.parametrize("extra, message", [
    (["--truth-features", "104S=f.csv"], "--truth-features needs --truth-design"),
    (["--truth-design", "no-such.csv"], "table no-such.csv does not exist"),
    (["--truth-design", "d.csv", "--truth-features", "104S=f.csv"], r"no --truth-features for shot\(s\) \['105S'\]"),
])
def test_check_cli_names_what_is_missing_in_the_hydrocode_truth(extra, message, monkeypatch, capsys):
    from pathlib import Path

    from shockcal.cli import main

    repo = Path(__file__).resolve().parents[1]
    monkeypatch.chdir(repo)                       # the config's record paths are relative to the repository
    argv = ["calibrate-check", "--config", "config/config.yaml", "--emulator", "no-such-dir", "--shots", "104S",
            "105S", "--out", "never.parquet", *extra]
    assert main(argv) == 2
    assert re.search(message, capsys.readouterr().err)


def test_every_sampler_setting_in_the_schema_has_the_librarys_minimum():
    """One set of rules behind both doors: each n_live and n_eff the config takes (the calibration, its
    check, the next-shot check, a sequential study's steps) has the minimum SamplerSettings refuses below."""
    from shockcal.inference.settings import MIN_N_EFF, MIN_N_LIVE
    from shockcal.study.config_files import load_schema

    found = []

    def walk(node, path):
        if isinstance(node, dict):
            for key, value in node.items():
                if key in ("n_live", "n_eff") and isinstance(value, dict) and "minimum" in value:
                    found.append((f"{path}.{key}", value["minimum"], MIN_N_LIVE if key == "n_live" else MIN_N_EFF))
                walk(value, f"{path}.{key}")

    walk(load_schema(), "")
    assert len(found) >= 8, found
    assert [f for f in found if f[1] != f[2]] == []
