"""The smooth emulator error variance (`emulator.sd_model: smooth`, `shockcal.emulator.variance_model`): on a
function whose scatter grows near one face of the box, its K-fold bands hold in every fifth of that
input's box where the constant sd factors' do not; it scales the covariance as D C D; it is saved,
loaded and refused in old files; the same seed gives the same model."""

import json

import numpy as np
import pytest

from shockcal.emulator.held_out import Z90
from shockcal.emulator.pcgp import EmulatorSettings, PCGPEmulator
from shockcal.emulator.variance_model import VarianceModel
from shockcal.errors import InputError

N = 400


def scatter_sd(x0):
    """The noise sd: 0.1 at the face x0 = 0, 0.01 from the middle of the box on."""
    return 0.01 * (1 + 9 * (1 - x0) ** 4)


def growing_noise(seed=0):
    """Two smooth outputs of three inputs with independent noise that grows tenfold near x0 = 0."""
    rng = np.random.default_rng(seed)
    X = rng.uniform(size=(N, 3))
    clean = np.column_stack([np.sin(2 * X[:, 0]) + X[:, 1] ** 2, 1 + 0.5 * X[:, 1] - 0.3 * X[:, 2] ** 2])
    return X, clean + scatter_sd(X[:, 0])[:, None] * rng.normal(size=(N, 2))


def fit(sd_model, seed=1):
    X, Y = growing_noise()
    return PCGPEmulator.fit(X, Y, np.zeros(3), np.ones(3), EmulatorSettings(n_starts=1, cv_folds=5, seed=seed, sd_model=sd_model, n_jobs=1))


@pytest.fixture(scope="module")
def models():
    return {sd_model: fit(sd_model) for sd_model in ("constant", "smooth")}


def coverage_by_fifth(model):
    """The cross-fitted K-fold's 90%-band coverage per fifth of x0's box (2 outputs x about 80 runs each)."""
    held = model.kfold
    inside = np.abs(held.mean - model.y_train[held.rows]) <= Z90 * held.sd
    fifth = np.clip((model.x_train[held.rows, 0] * 5).astype(int), 0, 4)
    return np.array([inside[fifth == k].mean() for k in range(5)]), np.bincount(fifth, minlength=5) * 2


def test_smooth_bands_hold_in_every_fifth_where_the_constant_ones_do_not(models):
    for sd_model, holds in (("smooth", True), ("constant", False)):
        coverage, counts = coverage_by_fifth(models[sd_model])
        band = 3 * np.sqrt(0.9 * 0.1 / counts)                  # binomial, 3 sd (the outputs' noise is independent)
        assert np.all(np.abs(coverage - 0.9) <= band) == holds, (sd_model, coverage.round(3), band.round(3))
    constant, _ = coverage_by_fifth(models["constant"])
    assert constant[0] < 0.8 and constant[-1] > 0.95               # too narrow at the face, too wide far from it


def test_the_smooth_sd_follows_the_noise_and_keeps_the_correlations(models):
    smooth, constant = models["smooth"], models["constant"]
    x = np.column_stack([np.linspace(0, 1, 11), np.full(11, 0.5), np.full(11, 0.5)])
    mean_s, cov_s = smooth.predict(x)
    mean_c, cov_c = constant.predict(x)
    np.testing.assert_array_equal(mean_s, mean_c)                   # the mean is not touched
    sd_s, sd_c = np.sqrt(np.einsum("nff->nf", cov_s)), np.sqrt(np.einsum("nff->nf", cov_c))
    np.testing.assert_allclose(cov_s / (sd_s[:, :, None] * sd_s[:, None, :]),
                               cov_c / (sd_c[:, :, None] * sd_c[:, None, :]), atol=1e-12)   # cov_ij s_i s_j
    assert sd_s[0, 0] > 3 * sd_s[-1, 0]                               # wider at the noisy face
    assert np.all(np.diff(sd_s[:6, 0]) < 0)                           # and narrowing smoothly away from it
    assert smooth.variance is not None and constant.variance is None


def test_saved_and_loaded_smooth_emulator_predicts_the_same(models, tmp_path):
    model = models["smooth"]
    loaded = PCGPEmulator.load(model.save(tmp_path / "emu.npz"))
    x = np.random.default_rng(3).uniform(size=(20, 3))
    for a, b in zip(model.predict(x), loaded.predict(x)):
        np.testing.assert_array_equal(a, b)
    assert loaded.variance.groups == model.variance.groups


def test_an_emulator_saved_before_the_smooth_sd_model_is_refused(models, tmp_path):
    path = models["constant"].save(tmp_path / "emu.npz")
    with np.load(path) as npz:
        arrays = dict(npz)
    header = json.loads(str(arrays.pop("header")))
    header["version"] = 4
    np.savez(path, header=np.array(json.dumps(header)), **arrays)
    with pytest.raises(InputError, match="version 4.*reads PC-GP emulators of version 5.*refit"):
        PCGPEmulator.load(path)


def test_same_seed_same_smooth_model(models):
    again = fit("smooth")
    for name, value in models["smooth"].to_arrays().items():
        np.testing.assert_array_equal(value, again.to_arrays()[name], err_msg=name)
    assert again.to_json() == models["smooth"].to_json()


def test_variance_model_recovers_a_known_log_variance():
    rng = np.random.default_rng(5)
    x = rng.uniform(size=(3000, 2))
    log_var = 2.0 * (1 - x[:, 0]) ** 2                                # grows towards x0 = 0, flat in x1
    z = np.exp(0.5 * log_var)[:, None] * rng.normal(size=(3000, 2))
    model = VarianceModel.fit(x, z, np.ones_like(z), [[0, 1]])
    grid = np.column_stack([np.linspace(0, 1, 6), np.full(6, 0.5)])
    g = model.log_variance(grid, np.ones((6, 2)))[:, 0]
    truth = 2.0 * (1 - grid[:, 0]) ** 2
    np.testing.assert_allclose(g - g.mean(), truth - truth.mean(), atol=0.25)


def test_unknown_sd_model_is_refused():
    with pytest.raises(InputError, match="sd_model 'linear'"):
        EmulatorSettings(sd_model="linear")
