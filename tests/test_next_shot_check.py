"""The realized check of the next-shot ranking (docs/next_shot.md, "The realized check"): the realized
gain's yardstick on Gaussians, the summary and its verdict on known numbers, the truths (seeded, reproducible,
inside the derived study's box), a candidate as a fourth shot added by config alone, the shared noise of the
check's calibrations, and bad input. The target end to end is tests/test_workflow.py's."""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from shockcal.campaign.candidates import SHEAR_MODULUS, VELOCITY
from shockcal.campaign.next_shot import normal_scores
from shockcal.campaign.ranking_check import check_summary, check_table, realized_gain, truth_design, verdict
from shockcal.cli import main
from shockcal.errors import ConfigError, InputError
from shockcal.hydro.material_library import load_material
from shockcal.study.adapters import candidate, candidate_box, input_box, shot_mapping, study_design
from shockcal.study.candidate_studies import check_candidates, check_inputs, derived_study_config, plan_check
from shockcal.study.config import input_names, prior_bounds
from shockcal.study.validate import validate_config

AL5083 = load_material("al5083")   # the paper's Al-5083, from the material library

REPO = Path(__file__).resolve().parents[1]
HOT = "104S-3.95x5.965mm-204ms-700K"
REPEAT = "106S-repeat"
TARGETS = ["A", "B", "C", "n", "m"]


def fake_posterior(config: dict, n: int = 300, seed: int = 0) -> pd.DataFrame:
    """Draws over the middle of the prior box, with lambda_y."""
    rng = np.random.default_rng(seed)
    draws = {name: rng.uniform(low + 0.3 * (high - low), high - 0.3 * (high - low), n)
             for name, (low, high) in prior_bounds(config).items()}
    draws["lambda_y"] = rng.gamma(5.0, 0.2, n)
    return pd.DataFrame(draws)


def truths_of(config: dict, posterior: pd.DataFrame, names=(HOT, REPEAT), n: int = 10, seed: int = 3):
    section = config["next_shot"]
    slope = section["shear_modulus_log_slope_per_K"]
    candidates = {name: (candidate(config, name), *check_inputs(config, name)) for name in names}
    return truth_design(posterior, input_names(config), candidates, n, seed, AL5083, section["velocity_sd_fraction"],
                        (slope["min"], slope["max"]), prior_bounds(config))


# --- the realized gain: the ranking's yardstick -------------------------------------------------------------

def test_the_references_own_normal_scores_are_its_rank_scores():
    x = np.random.default_rng(0).gamma(2.0, size=(500, 2))
    np.testing.assert_allclose(normal_scores(x, x), stats.norm.ppf((stats.rankdata(x, axis=0) - 0.5) / 500))


def test_realized_gain_of_gaussians_is_the_log_ratio_of_their_sds():
    rng = np.random.default_rng(1)
    reference = rng.normal(size=(20000, 2))
    before = rng.normal(size=(4000, 2))
    after = rng.normal(size=(4000, 2)) * [0.5, 0.25]
    # independent Gaussian targets: 0.5 log det shrinks by ln 2 + ln 4 (sd error of each log sd ~ 0.011)
    assert realized_gain(reference, before, after) == pytest.approx(np.log(2) + np.log(4), abs=0.05)
    assert realized_gain(reference[:, :1], before[:, :1], after[:, :1]) == pytest.approx(np.log(2), abs=0.04)
    # a monotone map of the parameters (exp) leaves the normal scores, hence the gain, as they are
    assert realized_gain(np.exp(reference), np.exp(before), np.exp(after)) == pytest.approx(
        realized_gain(reference, before, after), abs=1e-12)


def test_check_table_pairs_each_truth_with_its_baseline():
    rng = np.random.default_rng(2)
    reference = pd.DataFrame({"m": rng.normal(size=5000)})
    baseline = pd.concat([pd.DataFrame({"run": run, "m": rng.normal(size=2000)}) for run in (0, 1, 2)])
    narrow = pd.concat([pd.DataFrame({"run": run, "m": 0.5 * rng.normal(size=2000)}) for run in (0, 2)])
    table = check_table(reference, baseline, {"best": narrow}, ["m"])
    assert table["run"].tolist() == [0, 2]                    # truth 1 did not finish with the candidate
    assert table["gain_nats"].to_numpy() == pytest.approx(np.log(2), abs=0.06)
    assert table["baseline_sd_m"].to_numpy() == pytest.approx(1.0, abs=0.05)
    assert table["sd_m"].to_numpy() == pytest.approx(0.5, abs=0.03)


# --- the summary and its verdict ------------------------------------------------------------------------------

def ranking_of(**eig) -> pd.DataFrame:
    rows = [{"candidate": name, "eig_nats": value, "prior_sd_m": 0.9, "expected_sd_m": 0.9 * np.exp(-value)}
            for name, value in eig.items()]
    return pd.DataFrame(rows)


def check_of(best_gain, worst_gain, best_sd, worst_sd) -> pd.DataFrame:
    rows = []
    for name, gains, sds in (("hot", best_gain, best_sd), ("repeat", worst_gain, worst_sd)):
        rows += [{"run": run, "candidate": name, "gain_nats": g, "baseline_sd_m": 0.9, "sd_m": s}
                 for run, (g, s) in enumerate(zip(gains, sds))]
    return pd.DataFrame(rows)


def test_summary_of_known_numbers_and_a_ranking_that_holds():
    check = check_of([1.0, 1.2, 0.9, 1.1], [0.1, 0.2, 0.0, 0.1], [0.3, 0.2, 0.35, 0.25], [0.8, 0.85, 0.9, 0.8])
    summary = check_summary(check, ranking_of(hot=1.3, repeat=0.2), "hot", "repeat", ["m"]).set_index(["row", "quantity"])
    gain = summary.loc[("hot", "gain_nats")]
    assert gain["predicted"] == 1.3 and gain["realized_mean"] == pytest.approx(1.05)
    assert gain["realized_se"] == pytest.approx(np.std([1.0, 1.2, 0.9, 1.1], ddof=1) / 2) and gain["n_truths"] == 4
    assert summary.loc[("hot", "sd_m"), "predicted"] == pytest.approx(0.9 * np.exp(-1.3))
    assert summary.loc[("repeat", "baseline_sd_m"), "predicted"] == 0.9
    difference = summary.loc[("hot - repeat", "gain_nats")]
    assert difference["predicted"] == pytest.approx(1.1)
    assert difference["realized_mean"] == pytest.approx(0.95)   # paired: 0.9, 1.0, 0.9, 1.0
    assert difference["realized_se"] == pytest.approx(np.std([0.9, 1.0, 0.9, 1.0], ddof=1) / 2)
    assert difference["verdict"] == "holds"
    ln_sd = summary.loc[("hot - repeat", "ln_sd_m")]
    assert ln_sd["predicted"] == pytest.approx(-1.1)
    assert ln_sd["realized_mean"] == pytest.approx(np.mean(np.log([0.3 / 0.8, 0.2 / 0.85, 0.35 / 0.9, 0.25 / 0.8])))
    assert ln_sd["verdict"] == "holds"


def test_a_reversed_or_noisy_difference_does_not_hold():
    reversed_ = check_of([0.1, 0.2, 0.0, 0.1], [1.0, 1.2, 0.9, 1.1], [0.8] * 4, [0.3] * 4)
    summary = check_summary(reversed_, ranking_of(hot=1.3, repeat=0.2), "hot", "repeat", ["m"])
    assert set(summary.loc[summary["row"] == "hot - repeat", "verdict"]) == {"does not hold"}
    noisy = check_of([1.0, -0.5, 1.5, 0.0], [0.1, 0.2, 0.0, 0.1], [0.3] * 4, [0.8] * 4)
    summary = check_summary(noisy, ranking_of(hot=1.3, repeat=0.2), "hot", "repeat", ["m"]).set_index(["row", "quantity"])
    assert summary.loc[("hot - repeat", "gain_nats"), "verdict"] == "does not hold"     # mean 0.4, se 0.45


@pytest.mark.parametrize("predicted, mean, se, expected", [
    (1.0, 0.5, 0.2, "holds"), (1.0, 0.5, 0.25, "does not hold"), (1.0, -0.5, 0.1, "does not hold"),
    (-1.0, -0.5, 0.1, "holds"), (0.0, 0.5, 0.1, "does not hold"), (1.0, float("nan"), float("nan"), "does not hold")])
def test_verdict_rule(predicted, mean, se, expected):
    assert verdict(predicted, mean, se) == expected


def test_a_summary_needs_two_truths_and_the_candidates_rows():
    check = check_of([1.0], [0.1], [0.3], [0.8])
    with pytest.raises(InputError, match="fewer than 2 truths"):
        check_summary(check, ranking_of(hot=1.3, repeat=0.2), "hot", "repeat", ["m"])
    with pytest.raises(InputError, match=r"ranking: no row of candidate\(s\) \['repeat'\]"):
        check_summary(check_of([1, 2], [0, 1], [1, 1], [1, 1]), ranking_of(hot=1.3), "hot", "repeat", ["m"])


# --- the candidates as fourth shots, and their truths ---------------------------------------------------------

def test_a_hot_candidate_becomes_a_fourth_shot_with_its_own_velocity_and_modulus_increment(paper_config, tmp_path):
    design_file = tmp_path / "design.parquet"
    study, source = study_design(paper_config)
    study.to_parquet(design_file)
    derived = derived_study_config(paper_config, HOT, design_file)
    velocity, increment = check_inputs(paper_config, HOT)
    assert shot_mapping(derived, HOT).inputs()[-3:] == [velocity, "G1", increment]
    assert derived["shots"][HOT]["initial_temperature_K"] == 700 and derived["observed"]["source"] == "synthetic"
    box = derived["inputs"][increment]             # G1 in [0.2, 0.5] Mbar times s in [-7.5e-4, -2.5e-4] /K times 402 K
    assert (box["min"], box["max"]) == pytest.approx((0.5 * -7.5e-4 * 402, 0.2 * -2.5e-4 * 402))
    assert derived["inputs"][velocity]["min"] == pytest.approx(0.0204 * (1 - 3**0.5 * 0.02))
    grown, _ = study_design(derived)
    pd.testing.assert_frame_equal(grown[study.columns], study)      # every existing column untouched
    assert grown[velocity].between(derived["inputs"][velocity]["min"], derived["inputs"][velocity]["max"]).all()
    # a repeat at room temperature reads its reference shot's modulus inputs as they are
    repeat = derived_study_config(paper_config, REPEAT, design_file)
    assert repeat["shots"][REPEAT]["shear_modulus_inputs"] == paper_config["shots"]["106S"]["shear_modulus_inputs"]
    assert check_inputs(paper_config, REPEAT) == (f"V_{REPEAT}", None)


def test_truths_are_seeded_reproducible_and_inside_the_derived_box(paper_config, tmp_path):
    posterior = fake_posterior(paper_config)
    truths, designs = truths_of(paper_config, posterior)
    again, _ = truths_of(paper_config, posterior)
    pd.testing.assert_frame_equal(truths, again)
    assert not truths.equals(truths_of(paper_config, posterior, seed=4)[0])
    assert len(truths) == 10 and truths["lambda_y"].isin(posterior["lambda_y"]).all()   # whole posterior rows
    design_file = tmp_path / "design.parquet"
    study_design(paper_config)[0].to_parquet(design_file)
    for name in (HOT, REPEAT):
        box = input_box(derived_study_config(paper_config, name, design_file)).bounds
        for column in check_inputs(paper_config, name):
            if column is not None:
                assert truths[column].between(*box[column]).all(), column
        # the fourth shot's modulus (reference inputs plus increment) is the ranking model's G_ref (1 + s dT)
        modulus = truths[list(shot_mapping(derived_study_config(paper_config, name, design_file), name)
                              .shear_modulus_inputs)].sum(axis=1)
        np.testing.assert_allclose(modulus, designs[name][SHEAR_MODULUS], rtol=1e-12)
        np.testing.assert_allclose(truths[f"V_{name}"], designs[name][VELOCITY])
        cbox = candidate_box(paper_config, name).bounds
        assert designs[name][SHEAR_MODULUS].between(*cbox[SHEAR_MODULUS]).all()


# --- the check's calibrations share their noise on the common shots -------------------------------------------

def test_truth_lambda_y_and_shared_noise_in_calibrate_check(paper_config):
    from test_calibration_check import FEATURES, ShotEmulator

    from shockcal.inference.coverage import HydroTruths, synthetic_truth
    from shockcal.study.adapters import calibration_settings

    # the sampler's least settings: what is checked (the truths' lambda_y and runs, the draws' columns) does
    # not depend on the run's size
    paper_config["calibration"]["check"].update(n_live=50, n_eff=100)
    emu = ShotEmulator(paper_config, shots=["toy"], emulator_sd=0.3)
    mean, _ = emu.predict({"A": np.array([0.004, 0.006]), "n": np.array([0.5, 0.7])}, ["toy"])
    design = pd.DataFrame({"run": [7, 9], "A": [0.004, 0.006], "n": [0.5, 0.7], "lambda_y": [0.8, 1.3]})
    features = pd.DataFrame(mean, columns=FEATURES).assign(run=[7, 9], status="ok")
    truths = HydroTruths(design, {"toy": features})
    settings = calibration_settings(paper_config, ["toy"], check=True)
    draws = []
    table = synthetic_truth(emu, ["toy"], settings, trials=2, seed=5, truths=truths, draws=draws)
    lam = table[table["parameter"] == "lambda_y"]
    assert lam["truth"].tolist() == [0.8, 1.3] and lam["run"].tolist() == [7, 9]       # the truth's own lambda_y
    assert (table["sd"] > 0).all() and {tuple(d["run"].unique()) for d in draws} == {(7,), (9,)}
    assert {"A", "n", "lambda_y", "trial", "run"} <= set(draws[0].columns)


# --- bad input: one line before any run -------------------------------------------------------------------------

def test_an_unknown_candidate_and_too_few_truths_are_config_errors(paper_config):
    bad = copy.deepcopy(paper_config)
    bad["next_shot"]["check"]["candidates"] = [HOT, "nowhere"]
    with pytest.raises(ConfigError, match="next_shot.check.candidates: unknown candidate 'nowhere'"):
        validate_config(bad)
    bad = copy.deepcopy(paper_config)
    bad["next_shot"]["check"]["n_truths"] = 1
    with pytest.raises(ConfigError, match="next_shot.check.n_truths"):
        validate_config(bad)


def test_the_candidates_are_the_rankings_best_and_worst_or_those_named(paper_config, tmp_path):
    ranking = tmp_path / "ranking.csv"
    with pytest.raises(InputError, match=f"{ranking}: missing: .*make next-shot"):
        check_candidates(paper_config, ranking)
    pd.DataFrame({"candidate": ["104S-repeat", HOT, REPEAT], "eig_nats": [0.25, 1.2, 0.17]}).to_csv(ranking, index=False)
    assert check_candidates(paper_config, ranking) == [HOT, REPEAT]
    paper_config["next_shot"]["check"]["candidates"] = ["105S-repeat", HOT]
    assert check_candidates(paper_config, tmp_path / "absent.csv") == ["105S-repeat", HOT]


def test_a_sequential_study_plans_its_check_on_wave_0_and_is_never_refused_for_it(paper_config, tmp_path):
    """In a study in waves the check's derived studies are Latin-hypercube ones on wave 0's design (the training
    run set). A check whose settings do not fit the study (more training runs than wave 0 has) refuses the check
    when it is asked for, in one line naming the key, and leaves the study alone otherwise: every run of a
    sequential study after `make next-shot` planned the check and stopped on design.file against waves."""
    paper_config["design"].update(strategy="waves", waves={**paper_config["design"]["waves"], "initial_runs": 150,
                                                            "runs_per_wave": 75, "max_runs": 300})
    validate_config(paper_config)
    design_file = tmp_path / "training" / "design.parquet"
    design_file.parent.mkdir()
    study_design(paper_config)[0].to_parquet(design_file)
    ranking = tmp_path / "ranking.csv"
    pd.DataFrame({"candidate": [HOT, REPEAT], "eig_nats": [1.2, 0.17]}).to_csv(ranking, index=False)
    paper_config["next_shot"]["check"]["n_training_runs"] = 150
    plans = plan_check(paper_config, ranking, design_file, tmp_path / "check", required=True)
    assert sorted(plans) == sorted([HOT, REPEAT])
    for plan in plans.values():
        assert plan["study"]["design"]["strategy"] == "lhs" and plan["study"]["design"]["file"] == str(design_file)
        assert len(plan["table"]) == 150 and Path(plan["config"]).is_file()
    paper_config["next_shot"]["check"]["n_training_runs"] = 300
    assert plan_check(paper_config, ranking, design_file, tmp_path / "check2", required=False) == {}
    with pytest.raises(ConfigError, match="^next_shot.check.n_training_runs: 300 is more than the training "
                                          "design's 150 rows$"):
        plan_check(paper_config, ranking, design_file, tmp_path / "check2", required=True)


def test_summary_command_names_a_missing_ranking(tmp_path, capsys):
    code = main(["next-shot-check-summary", "--config", str(REPO / "config" / "config.yaml"), "--ranking",
                 str(tmp_path / "ranking.csv"), "--posterior", "p.parquet", "--baseline", "b.parquet",
                 "--candidates", "a=a.parquet", "b=b2.parquet", "--out", str(tmp_path / "check.csv")])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and "ranking.csv: missing" in err
