"""Next-shot candidates: the config's candidates and their bad input, a candidate's design
from the joint posterior, the elastic-plastic split, the score and the ranking `shockcal suggest-shot`
writes (docs/next_shot.md). The estimator itself is tests/test_next_shot.py's; the workflow target
end to end is tests/test_workflow.py's."""

from __future__ import annotations

import contextlib
import copy
import io
import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest
import yaml

from shockcal.campaign.candidates import (
    SHEAR_MODULUS,
    SLOPE,
    VELOCITY,
    VELOCITY_FACTOR,
    candidate_design,
    check_split,
    hel_particle_velocity_m_s,
    ranking_table,
    score_candidate,
)
from shockcal.cli import main
from shockcal.errors import ConfigError, InputError
from shockcal.hydro.material_library import load_material
from shockcal.io import write_table
from shockcal.study.adapters import candidate
from shockcal.study.config import candidate_config, input_names, prior_bounds
from shockcal.study.strength_config import next_shot_targets
from shockcal.study.validate import validate_config
from shockcal.velocimetry.columns import CALIBRATION_FEATURES

AL5083 = load_material("al5083")   # the paper's Al-5083, from the material library

REPO = Path(__file__).resolve().parents[1]
HOT = "104S-3.95x5.965mm-204ms-700K"


def fake_posterior(config: dict, n: int = 400, seed: int = 0) -> pd.DataFrame:
    """Draws spread over the middle of the prior box (A, C, m low enough for 104S's waves to split)."""
    rng = np.random.default_rng(seed)
    draws = {}
    for name, (low, high) in prior_bounds(config).items():
        draws[name] = rng.uniform(low + 0.3 * (high - low), high - 0.3 * (high - low), n)
    draws["A"] = rng.uniform(0.0015, 0.0025, n)
    draws["lambda_y"] = rng.gamma(5.0, 0.2, n)
    return pd.DataFrame(draws)


def design_of(config: dict, name: str, posterior: pd.DataFrame, n: int = 200, seed: int = 7) -> pd.DataFrame:
    section = config["next_shot"]
    slope = section["shear_modulus_log_slope_per_K"]
    return candidate_design(posterior, input_names(config), candidate(config, name), n, seed, AL5083,
                            section["velocity_sd_fraction"], (slope["min"], slope["max"]), prior_bounds(config))


# --- the config -------------------------------------------------------------------------------------------------

def test_default_candidates_are_the_papers_question(paper_config):
    candidates = paper_config["next_shot"]["candidates"]
    hot = [c for c in candidates.values() if c.get("initial_temperature_K")]
    assert len(candidates) == 7 and sorted(c["initial_temperature_K"] for c in hot) == [400, 500, 600, 700]
    assert {c["shot"] for c in candidates.values()} == {"104S", "105S", "106S"}
    assert next_shot_targets(paper_config) == ["A", "B", "C", "n", "m"] and paper_config["next_shot"]["n_draws"] == 200
    # a repeat keeps its shot's window; 104S's plates keep 104S's at any temperature
    assert candidate_config(paper_config, "105S-repeat")["analysis"]["window_after_arrival_us"] == 1.0
    assert candidate_config(paper_config, HOT)["analysis"]["window_after_arrival_us"] == 1.1
    assert validate_config(paper_config)["next_shot"]["candidates"] == candidates    # a second validation adds nothing


def test_a_thicker_flyer_gets_a_longer_window_in_proportion_to_its_plateau(paper_config):
    paper_config["next_shot"]["candidates"]["thick"] = {"shot": "104S", "flyer_mm": 7.9, "target_mm": 5.965,
                                                        "velocity_m_s": 204}
    validate_config(paper_config)
    window = candidate_config(paper_config, "thick")["analysis"]["window_after_arrival_us"]
    assert window == pytest.approx(2 * 1.1, rel=1e-12)        # the plateau (flyer/c_bulk + flyer/c_L) doubles


def _candidate(**changes) -> dict:
    return {"shot": "104S", "flyer_mm": 3.95, "target_mm": 5.965, "velocity_m_s": 204, **changes}


@pytest.mark.parametrize(
    "change, message",
    [
        ({"candidates": {"x": _candidate(initial_temperature_K=900)}},
         r"next_shot\.candidates\.x\.initial_temperature_K: 900 K is at or above material\.T_melt_K"),
        ({"targets": ["m", "q"]}, r"next_shot\.targets: unknown target 'q'"),
        ({"candidates": {"x": _candidate(shot="107S")}}, r"next_shot\.candidates\.x\.shot: '107S' is not a shot"),
        ({"candidates": {"104S": _candidate()}}, r"next_shot\.candidates\.104S: '104S' is also a shot's name"),
        ({"candidates": {"x": _candidate(window_after_arrival_us=1.5)}},
         r"next_shot\.candidates\.x\.analysis\.window_after_arrival_us: 1\.5 us reaches the release"),
        ({"candidates": {"x": _candidate(flyer_mm=1.0, target_mm=12.0)}},
         r"next_shot\.candidates\.x: the plastic wave reaches the free surface .* too thin for a plateau"),
        ({"candidates": {"x": _candidate(velocity_m_s=-5)}}, r"next_shot\.candidates\.x\.velocity_m_s: -5"),
        ({"readout_sd_m_s": {"t_elastic": 1.0}}, r"next_shot\.readout_sd_m_s: t_elastic: not a calibration feature"),
        ({"shear_modulus_log_slope_per_K": {"min": 0.0, "max": -1e-3}},
         r"next_shot\.shear_modulus_log_slope_per_K\.max: -0\.001 is below min \(0\)"),
        ({"targets": ["m", "m"]}, r"next_shot\.targets: \['m', 'm'\] names a target twice"),
        ({"check": {"candidates": ["104S-repeat", "104S-repeat"]}},
         r"next_shot\.check\.candidates: compares 104S-repeat with itself"),
    ],
)
def test_bad_candidates_are_named_before_any_run(paper_config, change, message):
    paper_config["next_shot"].update(copy.deepcopy(change))
    with pytest.raises(ConfigError, match=message) as caught:
        validate_config(paper_config, source="config.yaml")
    assert "\n" not in str(caught.value)


def test_an_unknown_candidate_is_named(paper_config):
    with pytest.raises(ConfigError, match=r"unknown next-shot candidate '107S-hot'; the config defines \["):
        candidate_config(paper_config, "107S-hot")


# --- a candidate's design ---------------------------------------------------------------------------------------

def test_every_candidate_gets_the_same_draws_and_its_own_velocity_and_modulus(paper_config):
    posterior = fake_posterior(paper_config)
    cold, hot = design_of(paper_config, "104S-repeat", posterior), design_of(paper_config, HOT, posterior)
    names = [*input_names(paper_config), "lambda_y", VELOCITY_FACTOR, SLOPE]
    pd.testing.assert_frame_equal(cold[["run", *names]], hot[["run", *names]])
    assert cold[SHEAR_MODULUS].equals(cold["G1"])                   # 298 K: the reference shot's G, unchanged
    heating = 700 - AL5083.T_ref_K
    np.testing.assert_allclose(hot[SHEAR_MODULUS], hot["G1"] * (1 + hot[SLOPE] * heating), rtol=1e-15)
    assert hot[SLOPE].between(-7.5e-4, -2.5e-4).all()
    factor = cold[VELOCITY_FACTOR]
    assert factor.between(1 - math.sqrt(3) * 0.02, 1 + math.sqrt(3) * 0.02).all()
    assert factor.std() == pytest.approx(0.02, rel=0.15)          # the stated sd (200 draws: 5% sampling error)
    np.testing.assert_allclose(cold[VELOCITY], 204e-4 * factor, rtol=1e-15)
    # the same seed gives the same design; another seed other rows
    assert design_of(paper_config, "104S-repeat", posterior).equals(cold)
    assert not design_of(paper_config, "104S-repeat", posterior, seed=8)["A"].equals(cold["A"])


def test_hel_particle_velocity_matches_poisson_form_and_104S_measurement(paper_config):
    """Independent of the code's (K + 4G/3) / 2G: sigma_HEL = Y (1 - nu) / (1 - 2 nu), nu from K and G; and the
    measured 104S precursor (SPEC Table I: sigma_HEL 0.6254 GPa, u_e 36.0 m/s) fixes u_e / sigma_HEL = 1 / (rho c_L)."""
    shot = candidate(paper_config, "104S-repeat")
    design = pd.DataFrame({"A": [0.00625 / 3.0], "C": [0.0], "m": [1.0], SHEAR_MODULUS: [0.269], VELOCITY: [0.0204]})
    k = AL5083.rho0_g_cc * (AL5083.bulk_sound_speed_m_s() / 1e4) ** 2
    nu = (3 * k - 2 * 0.269) / (2 * (3 * k + 0.269))
    sigma = design["A"].iloc[0] * (1 - nu) / (1 - 2 * nu)            # Mbar
    c_l = math.sqrt(k / AL5083.rho0_g_cc + 4 * 0.269 / (3 * AL5083.rho0_g_cc))
    u_e = hel_particle_velocity_m_s(design, shot, AL5083)[0]
    assert u_e == pytest.approx(sigma / (AL5083.rho0_g_cc * c_l) * 1e4, rel=1e-12)
    assert u_e / (sigma * 100) == pytest.approx(36.0 / 0.6254, rel=0.05)   # m/s per GPa, against the measurement


def test_a_velocity_without_a_plastic_wave_is_refused_before_any_run(paper_config):
    posterior = fake_posterior(paper_config)
    design = design_of(paper_config, "104S-repeat", posterior)
    check_split(design, candidate(paper_config, "104S-repeat"), AL5083, "next_shot.candidates.104S-repeat")
    slow = paper_config["next_shot"]["candidates"]["104S-repeat"] | {"velocity_m_s": 40}
    paper_config["next_shot"]["candidates"]["slow"] = slow
    with pytest.raises(InputError, match=r"next_shot\.candidates\.slow: velocity_m_s 40 .* no plastic wave") as caught:
        check_split(design_of(paper_config, "slow", posterior), candidate(paper_config, "slow"), AL5083,
                    "next_shot.candidates.slow")
    assert "\n" not in str(caught.value)


# --- the score and the ranking ----------------------------------------------------------------------------------

def linear_features(design: pd.DataFrame, gain: float, rng) -> pd.DataFrame:
    """Four 'features' (m/s) linear in m (scaled by `gain`) and A, with a little scatter."""
    base = 100 + gain * 10 * design["m"].to_numpy() + 2000 * design["A"].to_numpy()
    values = {f: base * (1 + 0.1 * j) + 0.1 * rng.standard_normal(len(design)) for j, f in enumerate(CALIBRATION_FEATURES)}
    return pd.DataFrame({"run": design["run"], "status": "ok", **values})


def test_the_more_sensitive_candidate_scores_higher_and_failed_runs_are_counted(paper_config):
    posterior = fake_posterior(paper_config)
    design = design_of(paper_config, "104S-repeat", posterior)
    rng = np.random.default_rng(3)
    parameters = [*input_names(paper_config), VELOCITY_FACTOR, SLOPE]
    scores = {}
    for gain in (0.2, 3.0):
        features = linear_features(design, gain, rng)
        features.loc[:4, "status"] = "failed"
        scores[gain] = score_candidate(features, design, CALIBRATION_FEATURES, parameters, ["A", "m"], 0.01,
                                       [0.0, 0.5, 0.0, 0.0], seed=5)
    weak, strong = scores[0.2], scores[3.0]
    assert weak["n_failed"] == strong["n_failed"] == 5 and weak["n_draws"] == len(design) - 5
    assert strong["eig_m_nats"] - 2 * strong["eig_m_sd"] > weak["eig_m_nats"] + 2 * weak["eig_m_sd"]
    assert strong["expected_sd_m"] < weak["expected_sd_m"] < weak["prior_sd_m"]
    features = linear_features(design, 3.0, np.random.default_rng(3))
    ok = features.iloc[5:]
    assert strong["feature_sd_v_elastic"] == pytest.approx(ok["v_elastic"].std(), rel=0.05)
    noise = np.sqrt((0.01 * ok["v_plastic"]) ** 2 / design["lambda_y"].iloc[5:] + 0.5**2)
    assert strong["noise_sd_v_plastic"] == pytest.approx(np.median(noise), rel=0.02)


def test_ranking_is_sorted_and_says_which_candidates_cannot_be_told_apart():
    rows = [{"candidate": "a", "eig_nats": 1.0, "eig_sd": 0.1}, {"candidate": "b", "eig_nats": 2.0, "eig_sd": 0.1},
            {"candidate": "c", "eig_nats": 1.75, "eig_sd": 0.05}]
    table = ranking_table(rows)
    assert list(table["candidate"]) == ["b", "c", "a"] and list(table["rank"]) == [1, 2, 3]
    assert list(table["overlaps_best"]) == [True, True, False]
    with pytest.raises(InputError, match="no candidates to rank"):
        ranking_table([])


# --- the commands -----------------------------------------------------------------------------------------------

def shockcal(*args):
    """`shockcal ARGS` in this process (the command line's exit code and its stderr)."""
    stderr = io.StringIO()
    with contextlib.redirect_stderr(stderr):
        code = main([str(a) for a in args])
    return SimpleNamespace(returncode=code, stderr=stderr.getvalue())


@pytest.fixture
def two_candidates(tmp_path, paper_config_readonly):
    """A config of two candidates (104S's plates at 298 and 700 K), a fake posterior, their designs and
    fake features in which the hot shot's features move with m ten times more."""
    config = copy.deepcopy(paper_config_readonly)
    config["next_shot"] = {"candidates": {"cold": _candidate(), "hot": _candidate(initial_temperature_K=700)},
                           "targets": ["A", "m"], "n_draws": 100, "emulator_error": False}
    text = yaml.safe_load((REPO / "config" / "config.yaml").read_text())
    text["next_shot"] = config["next_shot"]
    path = tmp_path / "config.yaml"
    path.write_text(yaml.safe_dump(text))
    config = validate_config(config)
    posterior = tmp_path / "joint.parquet"
    write_table(fake_posterior(config), posterior, {"shots": list(config["shots"])})
    files = {}
    for name, gain in (("cold", 0.3), ("hot", 3.0)):
        design = tmp_path / f"{name}.parquet"
        done = shockcal("next-shot-design", "--config", path, "--candidate", name, "--posterior", posterior,
                        "--out", design)
        assert done.returncode == 0, done.stderr
        features = tmp_path / f"{name}_features.parquet"
        write_table(linear_features(pd.read_parquet(design), gain, np.random.default_rng(1)), features)
        files[name] = (design, features)
    return path, posterior, files


def test_suggest_shot_writes_the_ranking_of_the_issue(tmp_path, two_candidates):
    path, _, files = two_candidates
    out = tmp_path / "next_shot" / "ranking.csv"
    done = shockcal("suggest-shot", "--config", path, "--designs", *(f"{n}={d}" for n, (d, _) in files.items()),
                    "--features", *(f"{n}={f}" for n, (_, f) in files.items()), "--out", out)
    assert done.returncode == 0, done.stderr
    ranking = pd.read_csv(out)
    assert list(ranking.columns[:7]) == ["candidate", "rank", "flyer_mm", "target_mm", "velocity_m_s",
                                         "initial_temperature_K", "eig_nats"]
    assert {"eig_sd", "expected_sd_A", "expected_sd_m", "eig_full_nats", "eig_full_lower_nats", "resolved",
            "eig_m_nats", "overlaps_best"} <= set(ranking.columns)
    assert list(ranking["candidate"]) == ["hot", "cold"] and list(ranking["initial_temperature_K"]) == [700, 298]
    again = tmp_path / "again.csv"
    shockcal("suggest-shot", "--config", path, "--designs", *(f"{n}={d}" for n, (d, _) in files.items()),
             "--features", *(f"{n}={f}" for n, (_, f) in files.items()), "--out", again)
    assert again.read_bytes() == out.read_bytes()                  # same config and seed, same bytes


def test_the_emulators_error_joins_the_noise_and_lowers_the_gain(tmp_path, two_candidates):
    path, _, files = two_candidates
    text = yaml.safe_load(path.read_text())
    text["next_shot"]["emulator_error"] = True
    path.write_text(yaml.safe_dump(text))
    pairs = ["--designs", *(f"{n}={d}" for n, (d, _) in files.items()),
             "--features", *(f"{n}={f}" for n, (_, f) in files.items())]
    rmse = tmp_path / "cv_rmse.csv"
    rows = [{"scheme": scheme, "shot": shot, "feature": f, "rmse_m_s": 2.0 if scheme == "kfold" else 9.0}
            for scheme in ("loo_closed_form", "kfold") for shot in ("104S", "105S") for f in CALIBRATION_FEATURES]
    pd.DataFrame(rows).to_csv(rmse, index=False)
    done = shockcal("suggest-shot", "--config", path, *pairs, "--out", tmp_path / "r.csv")
    assert done.returncode == 2 and "next_shot.emulator_error is true: give the emulator's RMSE table" in done.stderr
    done = shockcal("suggest-shot", "--config", path, *pairs, "--emulator-rmse", rmse, "--out", tmp_path / "r.csv")
    assert done.returncode == 0, done.stderr
    with_model = pd.read_csv(tmp_path / "r.csv").set_index("candidate")
    text["next_shot"]["emulator_error"] = False
    path.write_text(yaml.safe_dump(text))
    shockcal("suggest-shot", "--config", path, *pairs, "--out", tmp_path / "plain.csv")
    plain = pd.read_csv(tmp_path / "plain.csv").set_index("candidate")
    for name in ("cold", "hot"):
        noise = plain.loc[name, "noise_sd_v_elastic"]
        assert with_model.loc[name, "noise_sd_v_elastic"] == pytest.approx(math.hypot(noise, 2.0), rel=0.02)
        assert with_model.loc[name, "eig_nats"] < plain.loc[name, "eig_nats"]
    pd.DataFrame(rows).query("shot == '105S'").to_csv(rmse, index=False)
    text["next_shot"]["emulator_error"] = True
    path.write_text(yaml.safe_dump(text))
    done = shockcal("suggest-shot", "--config", path, *pairs, "--emulator-rmse", rmse, "--out", tmp_path / "x.csv")
    assert done.returncode == 2 and "no kfold RMSE of shot 104S's v_elastic" in done.stderr


def test_a_candidate_takes_its_reference_shots_readout_error_unless_the_config_gives_one(tmp_path, two_candidates):
    path, _, files = two_candidates
    pairs = ["--designs", *(f"{n}={d}" for n, (d, _) in files.items()),
             "--features", *(f"{n}={f}" for n, (_, f) in files.items())]
    observed = tmp_path / "observed.parquet"
    readout = {"readout_sd_v_elastic": 3.0, "readout_sd_v_plastic": 0.5, "readout_sd_v_slope1": 4.0,
               "readout_sd_v_slope2": 1.0}
    write_table(pd.DataFrame([{"shot": "104S", **readout}, {"shot": "105S", **{k: 0.0 for k in readout}}]), observed)
    shockcal("suggest-shot", "--config", path, *pairs, "--out", tmp_path / "plain.csv")
    done = shockcal("suggest-shot", "--config", path, *pairs, "--observed", observed, "--out", tmp_path / "r.csv")
    assert done.returncode == 0, done.stderr
    plain = pd.read_csv(tmp_path / "plain.csv").set_index("candidate")
    with_readout = pd.read_csv(tmp_path / "r.csv").set_index("candidate")
    for name in ("cold", "hot"):                                    # both candidates' reference shot is 104S
        for feature in CALIBRATION_FEATURES:
            noise = plain.loc[name, f"noise_sd_{feature}"]
            assert with_readout.loc[name, f"noise_sd_{feature}"] == pytest.approx(
                math.hypot(noise, readout[f"readout_sd_{feature}"]), rel=0.02)
        assert with_readout.loc[name, "eig_nats"] < plain.loc[name, "eig_nats"]
    text = yaml.safe_load(path.read_text())                       # a value in the config wins over the table's
    text["next_shot"]["readout_sd_m_s"] = {"v_slope1": 0.0}
    path.write_text(yaml.safe_dump(text))
    shockcal("suggest-shot", "--config", path, *pairs, "--observed", observed, "--out", tmp_path / "given.csv")
    given = pd.read_csv(tmp_path / "given.csv").set_index("candidate")
    assert given.loc["cold", "noise_sd_v_slope1"] == pytest.approx(plain.loc["cold", "noise_sd_v_slope1"], rel=0.02)
    write_table(pd.DataFrame([{"shot": "105S", **readout}]), observed)
    done = shockcal("suggest-shot", "--config", path, *pairs, "--observed", observed, "--out", tmp_path / "x.csv")
    assert done.returncode == 2 and "observed.parquet: no row for shot 104S" in done.stderr


def test_missing_posterior_and_missing_features_are_one_line(tmp_path, two_candidates):
    path, _, files = two_candidates
    done = shockcal("next-shot-design", "--config", path, "--candidate", "cold", "--posterior", tmp_path / "none.parquet",
                    "--out", tmp_path / "d.parquet")
    assert done.returncode == 2 and done.stderr.strip().count("\n") == 0
    assert "none.parquet does not exist" in done.stderr
    done = shockcal("suggest-shot", "--config", path, "--designs", *(f"{n}={d}" for n, (d, _) in files.items()),
                    "--features", f"cold={files['cold'][1]}", "--out", tmp_path / "r.csv")
    assert done.returncode == 2 and "--features: no table for candidate(s) ['hot']" in done.stderr
    assert done.stderr.strip().count("\n") == 0
