"""PCGPEmulator on plain arrays: each correlation family recovers a known map with calibrated bands;
K-fold equals brute-force refits; save/load; `shockcal predict-emulator`."""

import numpy as np
import pandas as pd
import pytest

from shockcal.emulator.correlation import FAMILIES, family_code, value_and_slope
from shockcal.emulator.gp import GaussianProcess
from shockcal.emulator.pcgp import EmulatorSettings, PCGPEmulator, Switch
from shockcal.study.adapters import emulator_spec

NOISE = 0.05


def known_map(x):
    """A smooth 3-input, 3-output map."""
    a, b, c = x.T
    return np.column_stack([np.sin(3 * a) + b**2, 2 * a * b + 0.5 * np.cos(2 * c), 1 + a - 0.7 * c**2])


@pytest.mark.parametrize("family", FAMILIES)
def test_each_family_recovers_a_known_function_with_calibrated_bands(family):
    rng = np.random.default_rng(4)
    x, x_new = rng.uniform(size=(120, 3)), rng.uniform(0.05, 0.95, size=(400, 3))
    y = np.sin(3 * x[:, 0]) + x[:, 1] ** 2 + NOISE * rng.normal(size=120)
    y_new = np.sin(3 * x_new[:, 0]) + x_new[:, 1] ** 2 + NOISE * rng.normal(size=400)
    gp = GaussianProcess.fit(x, y, n_starts=1, family=family, fit_mean=True)
    mean, var = gp.predict(x_new)
    assert np.sqrt(np.mean((mean - y_new) ** 2)) < 1.5 * NOISE
    inside = np.abs(mean - y_new) <= 1.6449 * np.sqrt(var)
    assert 0.85 <= inside.mean() <= 0.95
    assert gp.hyper.beta[2] < 0.1 * gp.hyper.beta[0]            # the unused input gets a long length scale


@pytest.mark.parametrize("family", FAMILIES)
def test_kernel_slope_is_the_derivative(family):
    r2 = np.array([1e-6, 0.01, 0.3, 1.0, 4.0])
    h = 1e-7
    code = family_code(family)
    c_and_slope = lambda r2: np.array([value_and_slope(r, code) for r in r2]).T      # noqa: E731
    c, slope = c_and_slope(r2)
    numeric = (c_and_slope(r2 + h)[0] - c_and_slope(r2 - h)[0]) / (2 * h)
    np.testing.assert_allclose(slope, numeric, rtol=1e-5)
    assert value_and_slope(0.0, code)[0] == 1.0


@pytest.mark.parametrize("family", FAMILIES)
def test_correlation_matrix_matches_the_formula(family):
    from scipy.spatial.distance import cdist

    from shockcal.emulator.gp import correlation

    rng = np.random.default_rng(7)
    a, b, beta = rng.uniform(size=(7, 3)), rng.uniform(size=(5, 3)), np.array([0.5, 4.0, 20.0])
    r = cdist(a * np.sqrt(beta), b * np.sqrt(beta))
    expected = {"gaussian": np.exp(-r**2), "matern52": (1 + np.sqrt(5) * r + 5 * r**2 / 3) * np.exp(-np.sqrt(5) * r),
                "matern32": (1 + np.sqrt(3) * r) * np.exp(-np.sqrt(3) * r)}[family]
    np.testing.assert_allclose(correlation(a, b, beta, family), expected, rtol=1e-12)


@pytest.mark.parametrize("family", FAMILIES)
def test_gradient_of_the_hyperparameter_posterior(family):
    from scipy.optimize import check_grad

    from shockcal.emulator.gp import neg_log_posterior

    rng = np.random.default_rng(5)
    x = rng.uniform(size=(30, 2))
    y = np.sin(4 * x[:, 0]) + 0.3 + 0.05 * rng.normal(size=30)
    phi = np.array([0.2, np.log(3.0), np.log(0.5), np.log(200.0)])
    for fit_mean in (False, True):
        args = (x, y, family, 1e-8, fit_mean)
        err = check_grad(lambda p, a=args: neg_log_posterior(p, *a)[0], lambda p, a=args: neg_log_posterior(p, *a)[1],
                         phi)
        assert err < 1e-4 * np.linalg.norm(neg_log_posterior(phi, x, y, family, 1e-8, fit_mean)[1]) + 1e-5


def _problem(n=60, seed=6):
    rng = np.random.default_rng(seed)
    lower, upper = np.array([1.0, -2.0, 10.0]), np.array([3.0, 2.0, 20.0])
    x = rng.uniform(size=(n, 3))
    return lower + x * (upper - lower), 100 * known_map(x) + NOISE * rng.normal(size=(n, 3)), lower, upper


@pytest.mark.parametrize("warm_start", [True, False])
def test_kfold_equals_brute_force_refits(warm_start):
    X, Y, lower, upper = _problem(n=24)
    settings = EmulatorSettings(family="matern52", n_starts=1, seed=3, calibrate_sd=False, cv_warm_start=warm_start, n_jobs=1)
    emulator = PCGPEmulator.fit(X, Y, lower, upper, settings)
    cv = emulator.cross_validate(4, seed=1)
    assert sorted(cv.rows) == list(range(24))
    folds = np.array_split(np.random.default_rng(1).permutation(24), 4)
    starts = [gp.hyper for gp in emulator.gps] if warm_start else None
    for fold in folds:
        train = np.setdiff1d(np.arange(24), fold)
        mean, cov = PCGPEmulator.fit(X[train], Y[train], lower, upper, settings, starts).predict(X[fold])
        at = [np.flatnonzero(cv.rows == r)[0] for r in fold]
        np.testing.assert_allclose(cv.mean[at], mean, rtol=1e-10, atol=1e-10)
        np.testing.assert_allclose(cv.sd[at], np.sqrt(np.einsum("nff->nf", cov)), rtol=1e-10)


def test_sd_calibration_is_one_factor_per_feature_from_the_kfold():
    X, Y, lower, upper = _problem(n=40)
    raw = PCGPEmulator.fit(X, Y, lower, upper, EmulatorSettings(n_starts=1, cv_folds=5, calibrate_sd=False, n_jobs=1))
    calibrated = PCGPEmulator.fit(X, Y, lower, upper, EmulatorSettings(n_starts=1, cv_folds=5, sd_model="constant", n_jobs=1))
    held = raw.cross_validate(5)
    z = np.abs(held.mean - Y[held.rows]) / held.sd
    np.testing.assert_allclose(calibrated.sd_factor, np.tile(np.quantile(z, 0.9, axis=0) / 1.6449, (2, 1)))
    (m0, c0), (m1, c1) = raw.predict(X[:5]), calibrated.predict(X[:5])
    np.testing.assert_array_equal(m0, m1)
    sd0, sd1 = np.sqrt(np.einsum("nff->nf", c0)), np.sqrt(np.einsum("nff->nf", c1))
    np.testing.assert_allclose(sd1, sd0 * calibrated.sd_factor[0])
    cv = calibrated.cross_validate(5)                     # each fold scaled by the other folds' factors
    assert np.all(cv.sd != held.sd) and np.array_equal(cv.mean, held.mean)


def test_a_switch_gets_its_own_sd_factor_and_its_bands_hold():
    # a known truth: output 0 scatters ten times more where output0 / output1 > 0.9 (a "single-wave" side)
    rng = np.random.default_rng(11)
    X = rng.uniform(size=(300, 2))
    clean = np.column_stack([0.5 + 0.6 * X[:, 0] + 0.1 * X[:, 1], np.ones(300)])
    past = clean[:, 0] > 0.9
    Y = clean + np.column_stack([np.where(past, 0.05, 0.005) * rng.normal(size=300), 0.005 * rng.normal(size=300)])
    settings = EmulatorSettings(n_starts=1, cv_folds=5, seed=2, n_jobs=1, sd_model="constant")
    switch = [Switch(0, 1, [0])]
    with_switch = PCGPEmulator.fit(X, Y, np.zeros(2), np.ones(2), settings, switches=switch)
    without = PCGPEmulator.fit(X, Y, np.zeros(2), np.ones(2), settings)
    assert with_switch.sd_factor[1, 0] > 2 * with_switch.sd_factor[0, 0]
    for model, holds in ((with_switch, True), (without, False)):
        held = model.kfold
        inside = np.abs(held.mean[:, 0] - Y[held.rows, 0]) <= 1.6449 * held.sd[:, 0]
        coverage = [inside[past[held.rows]].mean(), inside[~past[held.rows]].mean()]
        assert (min(coverage) >= 0.8 and max(coverage) <= 0.98) == holds, coverage
    mean, cov = with_switch.predict(np.array([[0.1, 0.5], [0.9, 0.5]]))     # below and past the switch
    sd = np.sqrt(cov[:, 0, 0])
    assert sd[1] > 3 * sd[0]


def test_arrays_api_fits_predicts_saves_and_loads(tmp_path):
    X, Y, lower, upper = _problem(n=60)
    emulator = PCGPEmulator.fit(X, Y, lower, upper, EmulatorSettings(n_starts=1, cv_folds=4, n_jobs=1, sd_model="constant"))
    X_new, Y_new, _, _ = _problem(n=50, seed=7)
    mean, cov = emulator.predict(X_new)
    assert mean.shape == (50, 3) and cov.shape == (50, 3, 3)
    assert np.sqrt(np.mean((mean - Y_new) ** 2)) < 3.0          # outputs span about 200
    assert np.all(np.linalg.eigvalsh(cov) > 0)
    loaded = PCGPEmulator.load(emulator.save(tmp_path / "emu.npz"))
    for a, b in zip(emulator.predict(X_new), loaded.predict(X_new)):
        np.testing.assert_array_equal(a, b)
    outer = emulator.outer_check(0.1)
    x = (X - lower) / (upper - lower)
    assert set(outer.rows) == set(np.flatnonzero(np.any((x < 0.1) | (x > 0.9), axis=1)))


def test_predict_emulator_writes_every_run_shot_and_feature(tmp_path, paper_config):
    import yaml

    from shockcal.cli import main
    from shockcal.design.tables import latin_hypercube
    from shockcal.emulator.study_emulator import Emulator, fit_emulator
    from shockcal.study.config import prior_bounds
    from shockcal.velocimetry.columns import CALIBRATION_FEATURES

    design = latin_hypercube(prior_bounds(paper_config), 30, 1)
    features = pd.DataFrame({f: 100 + 50 * design["A"] / 0.01 + 10 * i + 1e3 * design["V1"]
                             for i, f in enumerate(CALIBRATION_FEATURES)}).assign(run=design["run"])
    paper_config["emulator"].update(n_starts=1, calibrate_sd=False)
    emulator = fit_emulator(design, {"104S": features, "105S": features},
                            emulator_spec(paper_config, ["104S", "105S"]))
    input_map = emulator.blocks[0].input_map
    strain, temperature = (paper_config["emulator"][k] for k in ("hardening_strain", "homologous_temperature"))
    np.testing.assert_allclose(input_map.raw(design)[:, -2:], np.column_stack([strain ** design["n"],
                                                                               temperature ** design["m"]]))
    assert np.all((input_map.scaled(design) >= 0) & (input_map.scaled(design) <= 1))
    emulator.save(tmp_path / "emu")
    new = latin_hypercube(prior_bounds(paper_config), 7, 2).assign(run=lambda d: d["run"] + 100)
    new.to_csv(tmp_path / "new.csv", index=False)
    (tmp_path / "c.yaml").write_text(yaml.safe_dump(paper_config))
    assert main(["predict-emulator", "--config", str(tmp_path / "c.yaml"), "--emulator", str(tmp_path / "emu"),
                 "--design", str(tmp_path / "new.csv"), "--out", str(tmp_path / "p.parquet")]) == 0
    table = pd.read_parquet(tmp_path / "p.parquet")
    assert list(table.columns) == ["run", "shot", *CALIBRATION_FEATURES, *(f"{f}_sd" for f in CALIBRATION_FEATURES)]
    assert len(table) == 7 * 2 and set(table["run"]) == set(new["run"])
    mean, cov = Emulator.load(tmp_path / "emu").predict({k: new[k].to_numpy() for k in new.columns}, ["105S"])
    row = table[(table["run"] == 103) & (table["shot"] == "105S")].iloc[0]
    assert row["v_slope1"] == pytest.approx(mean[3, 2]) and row["v_slope1_sd"] == pytest.approx(np.sqrt(cov[3, 2, 2]))


def test_same_seed_gives_the_same_emulator_and_another_seed_another_fit_subset():
    # the fit subset (max_fit_runs < runs), the GP starts and the K-fold all come from settings.seed
    X, Y, lower, upper = _problem(n=40)
    fit = lambda seed: PCGPEmulator.fit(X, Y, lower, upper, EmulatorSettings(n_starts=2, cv_folds=4, max_fit_runs=30,  # noqa: E731
                                                                     seed=seed, n_jobs=1, sd_model="constant"))
    a, b, c = fit(5), fit(5), fit(6)
    for name, value in a.to_arrays().items():
        np.testing.assert_array_equal(value, b.to_arrays()[name], err_msg=name)
    assert a.to_json() == b.to_json()
    assert a.to_json() != c.to_json()


def test_prediction_solves_on_one_blas_thread_and_equals_each_components_own(monkeypatch):
    """The components' triangular solves run on one BLAS thread each (on two, a 1000-run solve cost
    2.2 times the CPU for no shorter wall time; docs/emulator.md "Speed"), spread over `n_jobs`
    Python threads, and give each component's own prediction at the rounding floor (rtol 1e-10): the batched
    solve and a component's own are two code paths, whose BLAS kernels may round differently (on an AMD
    EPYC 5 of 750 variances differ at 1e-11)."""
    from threadpoolctl import threadpool_info

    X, Y, lower, upper = _problem(n=60)
    emulator = PCGPEmulator.fit(X, Y, lower, upper, EmulatorSettings(n_starts=1, cv_folds=4, n_jobs=2, sd_model="constant"))
    x_new = emulator.scaled(_problem(n=250, seed=7)[0])
    expected = [gp.predict(x_new) for gp in emulator.gps]
    threads = []
    solve = GaussianProcess.predict_from_cross_cov

    def counted(self, k, include_nugget=True):
        threads.append(max(pool["num_threads"] for pool in threadpool_info() if pool["user_api"] == "blas"))
        return solve(self, k, include_nugget)

    monkeypatch.setattr(GaussianProcess, "predict_from_cross_cov", counted)
    mean, var = emulator._predict_weights(x_new)
    assert threads and set(threads) == {1}
    np.testing.assert_allclose(mean, np.column_stack([m for m, _ in expected]), rtol=1e-10, atol=0)
    np.testing.assert_allclose(var, np.column_stack([v for _, v in expected]), rtol=1e-10, atol=0)
