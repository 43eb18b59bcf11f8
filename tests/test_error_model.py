"""The emulator's error model: the Student t density against scipy, its fit against known truths, the
calibration likelihood built from it, and an emulator that carries it through save and load."""

import numpy as np
import pytest
from scipy import integrate, linalg, special, stats

from shockcal.emulator.error_model import ErrorModel
from shockcal.emulator.pcgp import EmulatorSettings, PCGPEmulator
from shockcal.inference.problem import Problem


def _spd(rng, f):
    a = rng.normal(size=(f, f))
    return a @ a.T + f * np.eye(f)


def _mixture_by_quad(resid, cov, noise_var, model):
    """log of the integral over w of N(resid; 0, scale cov / w + diag(noise_var)) Gamma(w; dof/2,
    rate dof/2), by scipy's adaptive quadrature in log w around the integrand's peak. The integrand is written
    out (Cholesky, the Gamma density's closed form): scipy's frozen densities cost 0.5 ms a call, 45 s of quadrature
    in all; it is checked against them at the peak."""
    half = model.dof / 2
    log_norm = half * np.log(half) - special.gammaln(half) - 0.5 * len(resid) * np.log(2 * np.pi)

    def log_integrand(t):
        factor = np.linalg.cholesky(model.scale * cov / np.exp(t) + np.diag(noise_var))
        z = linalg.solve_triangular(factor, resid, lower=True)
        return log_norm - 0.5 * z @ z - np.log(np.diag(factor)).sum() + (half - 1) * t - half * np.exp(t) + t

    def log_integrand_by_scipy(t):
        gauss = stats.multivariate_normal(np.zeros(len(resid)), model.scale * cov / np.exp(t) + np.diag(noise_var))
        return gauss.logpdf(resid) + stats.gamma(half, scale=1 / half).logpdf(np.exp(t)) + t

    grid = np.linspace(-35, 8, 861)
    peak_at = grid[np.argmax([log_integrand(t) for t in grid])]
    peak = log_integrand(peak_at)
    assert peak == pytest.approx(log_integrand_by_scipy(peak_at), rel=1e-12, abs=1e-12)
    value, _ = integrate.quad(lambda t: np.exp(log_integrand(t) - peak), -35, 8, points=[peak_at], limit=500,
                              epsabs=0, epsrel=1e-11)
    return np.log(value) + peak


@pytest.mark.parametrize("dof", [1.5, 6.0, 40.0, 900.0])
@pytest.mark.parametrize("noise", [0.01, 1.0, 100.0])
def test_error_plus_noise_density_matches_adaptive_quadrature(dof, noise):
    """Residuals from typical to 100 sd out, noise from negligible to dominant: within 1e-8."""
    rng = np.random.default_rng(int(dof * 10) + int(noise * 100))
    cov = _spd(rng, 4)
    noise_var = noise * np.diag(cov) * rng.uniform(0.5, 2.0, 4)
    resid = rng.multivariate_normal(np.zeros(4), cov + np.diag(noise_var), size=5) * np.array([[0.3, 1, 3, 10, 100]]).T
    model = ErrorModel(dof, 0.7)
    got = model.log_density(resid, np.broadcast_to(cov, (5, 4, 4)), np.broadcast_to(noise_var, (5, 4)))
    want = [_mixture_by_quad(r, cov, noise_var, model) for r in resid]
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-8)


@pytest.mark.parametrize("dof", [3.0, np.inf])
def test_closed_forms_match_scipy(dof):
    """Without noise the density is scipy's multivariate t; at infinite dof a Gaussian on scale C + noise."""
    rng = np.random.default_rng(0)
    cov, noise_var = _spd(rng, 4), rng.uniform(0.5, 2.0, 4)
    resid = 3.0 * rng.normal(size=(5, 4))
    model, covs = ErrorModel(dof, 0.7), np.broadcast_to(cov, (5, 4, 4))
    if np.isinf(dof):
        got = model.log_density(resid, covs, np.broadcast_to(noise_var, (5, 4)))
        want = stats.multivariate_normal(np.zeros(4), 0.7 * cov + np.diag(noise_var)).logpdf(resid)
    else:
        got, want = model.log_density(resid, covs), stats.multivariate_t(np.zeros(4), 0.7 * cov, df=dof).logpdf(resid)
    np.testing.assert_allclose(got, want, rtol=1e-12)


def test_log_density_is_nan_only_where_the_matrix_is_not_positive_definite():
    cov = np.stack([np.eye(2), np.array([[1.0, 2.0], [2.0, 1.0]]), np.full((2, 2), np.nan)])
    for noise_var in [None, np.ones((3, 2))]:
        value = ErrorModel(5.0).log_density(np.ones((3, 2)), cov, noise_var)
        assert np.isfinite(value[0]) and np.isnan(value[1:]).all()


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
    """Two independent groups: the Problem's log-likelihood is the sum of each group's density of its
    residual (emulator error plus observation noise of variance obs_sd^2 / lambda_y)."""
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
        (t_cols, t_model), (g_cols, g_model) = groups
        noise_var = (0.01 * observed) ** 2 / lam[i]
        want[i] = _mixture_by_quad(observed[t_cols] - means[i, t_cols], cov[np.ix_(t_cols, t_cols)],
                                   noise_var[t_cols], t_model)
        want[i] += stats.multivariate_normal(np.zeros(2), 1.2 * cov[np.ix_(g_cols, g_cols)]
                                             + np.diag(noise_var[g_cols])).logpdf(observed[g_cols] - means[i, g_cols])
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-8)


def test_emulator_fits_the_error_model_to_its_kfold_and_keeps_it(tmp_path):
    """The fitted model is the fit of the emulator's own cross-fitted K-fold distances; it survives
    save and load; gaussian tails keep the Gaussian."""
    rng = np.random.default_rng(4)
    X = rng.uniform(size=(120, 2))
    Y = np.column_stack([np.sin(3 * X[:, 0]) + X[:, 1], np.cos(2 * X[:, 1]) + X[:, 0] ** 2])
    emu = PCGPEmulator.fit(X, Y, np.zeros(2), np.ones(2), EmulatorSettings(n_starts=1, cv_folds=5, n_jobs=1, sd_model="constant"))
    held = emu.cross_validate(5)
    assert held.cov is not None and len(held.rows) == 120
    assert emu.error == ErrorModel.fit(*held.distances(Y)) and np.isfinite(emu.error.dof)
    loaded = PCGPEmulator.load(emu.save(tmp_path / "emu.npz"))
    assert loaded.error == emu.error
    gaussian = PCGPEmulator.fit(X, Y, np.zeros(2), np.ones(2), EmulatorSettings(n_starts=1, cv_folds=5, error_tails="gaussian", n_jobs=1,
                                                                                sd_model="constant"))
    assert gaussian.error == ErrorModel()
