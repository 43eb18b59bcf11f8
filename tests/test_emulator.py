"""PC-GP emulator: known functions, closed-form LOO, calibrated bands, file format, bad input."""

import json

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from shockcal.emulator.gp import GaussianProcess
from shockcal.emulator.heldout import region_coverage, score_heldout
from shockcal.emulator.study_emulator import Emulator, fit_emulator, rmse_table
from shockcal.errors import InputError
from shockcal.study.adapters import emulator_spec
from shockcal.study.config import prior_bounds
from shockcal.velocimetry.columns import CALIBRATION_FEATURES

NOISE = 0.05


def known_function(x):
    """A smooth 3-input, 4-output map (m/s-like scale)."""
    a, b, c = x.T
    return np.column_stack([60 + 20 * a + 5 * np.sin(3 * b), 200 + 10 * a * b, 80 + 15 * np.cos(2 * c) + 8 * a,
                            190 + 12 * b + 4 * c**2])


def test_gp_recovers_a_known_function_with_loo_error_near_the_noise():
    rng = np.random.default_rng(1)
    x = rng.uniform(size=(80, 3))
    y = np.sin(3 * x[:, 0]) + x[:, 1] ** 2 + NOISE * rng.normal(size=80)
    gp = GaussianProcess.fit(x, y, n_starts=2)
    mean, var = gp.loo()
    rmse = np.sqrt(np.mean((mean - y) ** 2))
    assert rmse < 1.5 * NOISE
    inside = np.abs(mean - y) <= 1.6449 * np.sqrt(var)
    assert 0.8 <= inside.mean() <= 0.98


def test_closed_form_loo_equals_brute_force_refitting():
    rng = np.random.default_rng(2)
    x = rng.uniform(size=(25, 3))
    y = np.cos(2 * x[:, 0]) * x[:, 2] + 0.01 * rng.normal(size=25)
    gp = GaussianProcess.fit(x, y, n_starts=1)
    loo_mean, loo_var = gp.loo()
    for i in range(25):
        keep = np.arange(25) != i
        mean, var = GaussianProcess(x[keep], y[keep], gp.hyper).predict(x[i:i + 1])
        assert mean[0] == pytest.approx(loo_mean[i], abs=1e-8)
        assert var[0] == pytest.approx(loo_var[i], abs=1e-8)


def _synthetic_study(paper_config, n=60, seed=3):
    """A design over the paper's box whose 104S features are a known function of A, B, n."""
    from shockcal.design.tables import latin_hypercube

    design = latin_hypercube(prior_bounds(paper_config), n, seed)
    lo = np.array([paper_config["inputs"][k]["min"] for k in ("A", "B", "n")])
    hi = np.array([paper_config["inputs"][k]["max"] for k in ("A", "B", "n")])
    x = (design[["A", "B", "n"]].to_numpy() - lo) / (hi - lo)
    rng = np.random.default_rng(seed)
    y = known_function(x) + NOISE * rng.normal(size=(n, 4))
    features = pd.DataFrame(y, columns=CALIBRATION_FEATURES).assign(run=design["run"], status="ok")
    return design, features, x


def test_emulator_predicts_a_known_map_and_its_bands_hold(paper_config):
    design, features, _ = _synthetic_study(paper_config, n=90)
    paper_config["emulator"].update(structure="per_shot", n_starts=2, cv_folds=5)
    emulator = fit_emulator(design, {"104S": features}, emulator_spec(paper_config, ["104S"]))
    table = rmse_table(emulator.cv_table())
    overall = table.iloc[-1]
    assert overall["rmse_m_s"] < 3 * NOISE
    assert 0.8 <= overall["coverage90"] <= 0.98
    new, _, x_new = _synthetic_study(paper_config, n=20, seed=9)
    mean, cov = emulator.predict({k: new[k].to_numpy() for k in new.columns}, ["104S"])
    assert mean.shape == (20, 4) and cov.shape == (20, 4, 4)
    assert np.sqrt(np.mean((mean - known_function(x_new)) ** 2)) < 4 * NOISE
    assert np.all(np.linalg.eigvalsh(cov) > 0)


def _fitted_and_unseen(paper_config):
    """A per-shot emulator of the known map on 90 runs, and 200 runs it never saw (design, features)."""
    design, features, _ = _synthetic_study(paper_config, n=90)
    paper_config["emulator"].update(structure="per_shot", n_starts=2, cv_folds=5)
    emulator = fit_emulator(design, {"104S": features}, emulator_spec(paper_config, ["104S"]))
    new, new_features, _ = _synthetic_study(paper_config, n=200, seed=9)
    return emulator, new, new_features


def test_heldout_score_is_the_error_and_band_share_at_unseen_runs(paper_config):
    emulator, new, new_features = _fitted_and_unseen(paper_config)
    table = score_heldout(emulator, new, {"104S": new_features})
    assert list(table["feature"]) == [f"104S:{f}" for f in CALIBRATION_FEATURES] + ["all (200 runs)"]
    assert table["rmse_m_s"].iloc[-1] < 4 * NOISE and 0.8 <= table["coverage"].iloc[-1] <= 0.98   # the bands hold
    mean, cov = emulator.predict({k: new[k].to_numpy() for k in new.columns}, ["104S"])
    sd = np.sqrt(np.diagonal(cov, axis1=1, axis2=2))
    error = emulator.blocks[0].model.error
    half = np.sqrt(error.scale) * stats.t.ppf(0.95, error.dof) * sd
    for shift, coverage in [(0.0, 1.0), (0.99, 1.0), (1.01, 0.0)]:     # just inside or outside the band
        exact = new_features.copy()
        exact[CALIBRATION_FEATURES] = mean + shift * half
        scored = score_heldout(emulator, new, {"104S": exact}).iloc[-1]
        assert scored["coverage"] == coverage
        assert scored["rmse_m_s"] == pytest.approx(np.sqrt(np.mean((shift * half) ** 2)), rel=1e-12, abs=1e-12)
        assert scored["mean_z2"] == pytest.approx(np.mean((shift * half / sd) ** 2), rel=1e-12, abs=1e-12)
    failed = new_features.assign(status=np.where(new_features["run"] < 10, "failed", "ok"))
    assert score_heldout(emulator, new, {"104S": failed})["n_values"].iloc[0] == 190


def test_region_coverage_is_the_share_of_runs_inside_the_error_models_region(paper_config):
    emulator, new, new_features = _fitted_and_unseen(paper_config)
    table = region_coverage(emulator, new, {"104S": new_features})
    assert table[["block", "n_features", "n_runs"]].to_dict("records") == [
        {"block": "104S", "n_features": 4, "n_runs": 200}]
    assert 0.8 <= table["coverage"].iloc[0] <= 0.98                     # the region holds unseen runs
    mean, cov = emulator.predict({k: new[k].to_numpy() for k in new.columns}, ["104S"])
    error = emulator.blocks[0].model.error
    limit = 4 * error.scale * stats.f.ppf(0.9, 4, error.dof)            # of e' C^-1 e, t_dof(0, scale C)
    direction = np.linalg.cholesky(cov) @ np.full(4, 0.5)               # e' C^-1 e = 1 along it
    for factor, inside in [(0.99, 1.0), (1.01, 0.0)]:                   # just inside or outside the region
        exact = new_features.copy()
        exact[CALIBRATION_FEATURES] = mean + np.sqrt(factor * limit) * direction
        assert region_coverage(emulator, new, {"104S": exact})["coverage"].iloc[0] == inside
    rng = np.random.default_rng(3)                                      # errors drawn from the error model itself
    drawn = new_features.copy()
    drawn[CALIBRATION_FEATURES] = [error.sample(m, c, rng) for m, c in zip(mean, cov)]
    assert abs(region_coverage(emulator, new, {"104S": drawn})["coverage"].iloc[0] - 0.9) < 3 * np.sqrt(0.09 / 200)


def test_saved_emulator_predicts_identically_and_refuses_other_versions(tmp_path, paper_config):
    design, features, _ = _synthetic_study(paper_config, n=30)
    paper_config["emulator"].update(n_starts=1, calibrate_sd=False)
    emulator = fit_emulator(design, {"104S": features, "106S": features},
                            emulator_spec(paper_config, ["104S", "106S"]))
    loaded = Emulator.load(emulator.save(tmp_path / "emu"))
    inputs = {k: design[k].to_numpy()[:5] for k in design.columns}
    for a, b in zip(emulator.predict(inputs, ["106S", "104S"]), loaded.predict(inputs, ["106S", "104S"])):
        np.testing.assert_array_equal(a, b)
    assert loaded.required_inputs(["106S"]) == ["A", "B", "C", "n", "m", "V3", "G1", "Delta2", "Delta3"]
    meta = json.loads((tmp_path / "emu" / "emulator.json").read_text())
    meta["version"] = 99
    (tmp_path / "emu" / "emulator.json").write_text(json.dumps(meta))
    with pytest.raises(InputError, match="version 99"):
        Emulator.load(tmp_path / "emu")
    with pytest.raises(InputError, match=r"no shot \['105S'\]"):
        loaded.predict(inputs, ["105S"])


def test_failed_and_nan_runs_are_dropped(paper_config, caplog):
    caplog.set_level("INFO", logger="shockcal.emulator.study_emulator")
    design, features, _ = _synthetic_study(paper_config, n=30)
    features.loc[0, "status"] = "failed"
    features.loc[1, "v_plastic"] = np.nan
    paper_config["emulator"].update(n_starts=1, calibrate_sd=False)
    emulator = fit_emulator(design, {"104S": features}, emulator_spec(paper_config, ["104S"]))
    assert len(emulator.blocks[0].runs) == 28
    assert "2 of 30 runs dropped" in caplog.text


@pytest.mark.parametrize("mutate, message", [
    (lambda d, f: (d, f.iloc[:8]), "at least 9"),
    (lambda d, f: (d.assign(C=0.01), f), "input C is constant"),
    (lambda d, f: (d, f.assign(run=f["run"] + 1000)), "not in the design"),
    (lambda d, f: (d.assign(A=d["A"] * 3), f), "outside the prior box"),
])
def test_bad_training_sets_are_rejected(paper_config, mutate, message):
    design, features = mutate(*_synthetic_study(paper_config, n=30)[:2])
    with pytest.raises(InputError, match=message):
        fit_emulator(design, {"104S": features}, emulator_spec(paper_config, ["104S"]))


def test_cli_fits_on_tables_and_writes_cv(tmp_path, paper_config):
    from shockcal.cli import main

    design, features, _ = _synthetic_study(paper_config, n=30)
    design.to_csv(tmp_path / "design.csv", index=False)
    features.to_parquet(tmp_path / "f.parquet")
    quick = tmp_path / "c.yaml"
    import yaml
    paper_config["emulator"].update(n_starts=1, cv_folds=3)
    quick.write_text(yaml.safe_dump(paper_config))
    assert main(["emulate", "--config", str(quick), "--design", str(tmp_path / "design.csv"),
                 "--features", f"104S={tmp_path / 'f.parquet'}", "--out", str(tmp_path / "emu")]) == 0
    cv = pd.read_parquet(tmp_path / "emu" / "cv.parquet")
    assert set(cv.columns) == {"run", "shot", "feature", "simulated", "predicted", "predicted_sd", "scheme"}
    assert len(cv) == 30 * 4 and set(cv["scheme"]) == {"loo_closed_form"}
    held = pd.read_parquet(tmp_path / "emu" / "cv_heldout.parquet")
    assert (held["scheme"] == "kfold").sum() == 30 * 4 and set(held["scheme"]) == {"kfold", "outer"}
    rmse = pd.read_csv(tmp_path / "emu" / "cv_rmse.csv")
    assert list(rmse.loc[rmse["shot"] == "all", "scheme"]) == ["loo_closed_form", "kfold", "outer"]
    assert main(["emulate-cv", "--emulator", str(tmp_path / "emu")]) == 0
    assert main(["emulate", "--config", str(quick), "--design", str(tmp_path / "design.csv"),
                 "--features", "104S", "--out", str(tmp_path / "x")]) == 2


def test_cli_first_runs_fits_on_the_designs_first_rows_only(tmp_path, paper_config, capsys):
    """`emulate --first-runs N` (the next-shot check's emulators): the design's first N rows, later runs' features
    left out; N outside 1..rows is one line."""
    import yaml

    from shockcal.cli import main
    from shockcal.emulator.study_emulator import Emulator

    design, features, _ = _synthetic_study(paper_config, n=30)
    design.to_csv(tmp_path / "design.csv", index=False)
    features.to_parquet(tmp_path / "f.parquet")
    paper_config["emulator"].update(n_starts=1, cv_folds=3)
    (tmp_path / "c.yaml").write_text(yaml.safe_dump(paper_config))
    common = ["emulate", "--config", str(tmp_path / "c.yaml"), "--design", str(tmp_path / "design.csv"),
              "--features", f"104S={tmp_path / 'f.parquet'}"]
    assert main([*common, "--first-runs", "20", "--out", str(tmp_path / "emu")]) == 0
    runs = Emulator.load(tmp_path / "emu").blocks[0].runs
    assert sorted(runs) == sorted(design["run"].iloc[:20])
    assert main([*common, "--first-runs", "31", "--out", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--first-runs: 31 is not between 1 and the design's 30 rows" in err[0]


def test_features_of_a_shot_the_spec_does_not_map_are_rejected(paper_config):
    design, features, _ = _synthetic_study(paper_config, n=30)
    with pytest.raises(InputError, match=r"features of shots \['106S'\]: the emulator spec maps only \['104S'\]"):
        fit_emulator(design, {"104S": features, "106S": features}, emulator_spec(paper_config, ["104S"]))
