"""The emulator's error model: the Student t density against scipy, its fit against known truths, the
calibration likelihood built from it, and an emulator that carries it through save and load."""

import numpy as np
import pytest
from scipy import stats

from shockcal.calibration import Problem
from shockcal.emulator import PCGPEmulator, Settings
from shockcal.error_model import ErrorModel


def _spd(rng, f):
    a = rng.normal(size=(f, f))
    return a @ a.T + f * np.eye(f)


@pytest.mark.parametrize("dof", [3.0, 12.5, np.inf])
def test_log_density_matches_scipy(dof):
    rng = np.random.default_rng(0)
    cov, noise = _spd(rng, 4), np.diag(rng.uniform(0.5, 2.0, 4))
    resid = 3.0 * rng.normal(size=(5, 4))
    got = ErrorModel(dof, 0.7).log_density(resid, np.broadcast_to(cov, (5, 4, 4)), np.broadcast_to(noise, (5, 4, 4)))
    shape = 0.7 * cov + noise
    want = (stats.multivariate_normal(np.zeros(4), shape).logpdf(resid) if np.isinf(dof)
            else stats.multivariate_t(np.zeros(4), shape, df=dof).logpdf(resid))
    np.testing.assert_allclose(got, want, rtol=1e-12)


def test_log_density_is_nan_only_where_the_matrix_is_not_positive_definite():
    cov = np.stack([np.eye(2), np.array([[1.0, 2.0], [2.0, 1.0]])])
    value = ErrorModel(5.0).log_density(np.ones((2, 2)), cov)
    assert np.isfinite(value[0]) and np.isnan(value[1])


@pytest.mark.parametrize("dof", [4.0, 8.0])
def test_fit_recovers_dof_and_scale_of_t_errors(dof):
    """Distances of t_dof(0, 0.7 C) errors under C: the fit finds dof and 0.7 within sampling error."""
    rng = np.random.default_rng(int(dof))
    f, n = 12, 3000
    z = rng.normal(size=(n, f)) * np.sqrt(0.7 / (rng.chisquare(dof, n) / dof))[:, None]
    fitted = ErrorModel.fit((z**2).sum(axis=1), f)
    assert fitted.dof == pytest.approx(dof, rel=0.25)
    assert fitted.scale == pytest.approx(0.7, rel=0.1)


def test_fit_of_gaussian_errors_gives_a_gaussian_for_every_purpose():
    rng = np.random.default_rng(1)
    fitted = ErrorModel.fit(rng.chisquare(12, 3000), 12)
    assert fitted.dof > 100 and fitted.scale == pytest.approx(1.0, rel=0.05)


def test_fit_refuses_too_few_or_bad_distances():
    with pytest.raises(ValueError, match="at least 10"):
        ErrorModel.fit(np.ones(5), 3)
    with pytest.raises(ValueError, match="at least 10"):
        ErrorModel.fit(np.r_[np.ones(20), np.nan], 3)


def test_samples_follow_the_model():
    """Draws' distances under scale * C follow F(F, dof) * F (KS), Gaussian draws chi-square."""
    rng = np.random.default_rng(2)
    cov = _spd(rng, 3)
    for model, dist in [(ErrorModel(5.0, 0.5), stats.f(3, 5.0, scale=3.0)), (ErrorModel(np.inf, 0.5), stats.chi2(3))]:
        draws = np.array([model.sample(np.zeros(3), cov, rng) for _ in range(2000)])
        d2 = np.einsum("ni,ij,nj->n", draws, np.linalg.inv(0.5 * cov), draws)
        assert stats.kstest(d2, dist.cdf).pvalue > 0.01


def test_likelihood_sums_one_density_per_error_group():
    """Two independent groups: the Problem's log-likelihood is the sum of each group's t density of
    its residual, with the observation noise added to the group's scale matrix."""
    rng = np.random.default_rng(3)
    cov = _spd(rng, 4)
    cov[:2, 2:] = cov[2:, :2] = 0.0
    observed = np.array([100.0, 200.0, 300.0, 400.0])
    means = observed + rng.normal(size=(6, 4))
    groups = [(np.array([0, 1]), ErrorModel(4.0, 0.9)), (np.array([2, 3]), ErrorModel(np.inf, 1.2))]
    problem = Problem(lambda theta: (means[:len(theta)], np.broadcast_to(cov, (len(theta), 4, 4)).copy()),
                      observed, 0.01 * observed, ["a"], np.zeros(1), np.ones(1), error_groups=groups)
    lam = rng.uniform(0.5, 2.0, 6)
    got = problem.log_likelihood(np.column_stack([np.full(6, 0.5), lam]))
    want = np.zeros(6)
    for i in range(6):
        for cols, error in groups:
            shape = error.scale * cov[np.ix_(cols, cols)] + np.diag((0.01 * observed[cols]) ** 2) / lam[i]
            dist = (stats.multivariate_normal(np.zeros(2), shape) if np.isinf(error.dof)
                    else stats.multivariate_t(np.zeros(2), shape, df=error.dof))
            want[i] += dist.logpdf(observed[cols] - means[i, cols])
    np.testing.assert_allclose(got, want, rtol=1e-12)


def test_emulator_fits_the_error_model_to_its_kfold_and_keeps_it(tmp_path):
    """The fitted model is the fit of the emulator's own cross-fitted K-fold distances; it survives
    save and load; gaussian tails keep the Gaussian."""
    rng = np.random.default_rng(4)
    X = rng.uniform(size=(120, 2))
    Y = np.column_stack([np.sin(3 * X[:, 0]) + X[:, 1], np.cos(2 * X[:, 1]) + X[:, 0] ** 2])
    emu = PCGPEmulator.fit(X, Y, np.zeros(2), np.ones(2), Settings(n_starts=1, cv_folds=5))
    held = emu.cross_validate(5)
    assert held.cov is not None and len(held.rows) == 120
    assert emu.error == ErrorModel.fit(*held.distances(Y)) and np.isfinite(emu.error.dof)
    loaded = PCGPEmulator.load(emu.save(tmp_path / "emu.npz"))
    assert loaded.error == emu.error
    gaussian = PCGPEmulator.fit(X, Y, np.zeros(2), np.ones(2), Settings(n_starts=1, cv_folds=5, error_tails="gaussian"))
    assert gaussian.error == ErrorModel()
