"""One Gaussian process over inputs in [0, 1]^d, hyperparameters at their posterior mode.

    cov(w(t), w(t')) = c(r^2) / lambda_w  +  delta(t, t') / lambda_n,   r^2 = sum_k beta_k (t_k - t'_k)^2

with a constant mean (estimated by generalised least squares, or fixed at 0). Correlation families
c (`correlation.FAMILIES`): `gaussian` exp(-r^2), Higdon et al.'s prod_k rho_k^(4 (t_k - t'_k)^2) with
rho_k = exp(-beta_k / 4); `matern52` and `matern32`, the Matern functions of r. Priors (SPEC
section 5): lambda_w ~ Gamma(5, 5), rho_k = exp(-beta_k / 4) ~ Beta(1, 0.1) for every family, nugget
precision lambda_n ~ Gamma(3, 0.003) as in GPM/SA. The mode is found in the coordinates
(log lambda_w, log beta_k, log lambda_n), Jacobian included, where the posterior is proper and
smooth (the Beta(1, 0.1) density itself is unbounded at rho = 1).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
from scipy import linalg, optimize

from shockcal.emulator.correlation import (
    correlation_and_slope,
    cross_correlation,
    family_code,
    gradient_sums,
)

LAMBDA_W_PRIOR = (5.0, 5.0)         # Gamma(shape, rate) of the marginal precision
RHO_PRIOR = (1.0, 0.1)              # Beta(a, b) of each rho_k
LAMBDA_N_PRIOR = (3.0, 0.003)       # Gamma(shape, rate) of the nugget precision
LOG_BOUNDS = {"lambda_w": (-6.0, 8.0), "beta": (np.log(1e-4), np.log(2e3)), "lambda_n": (0.0, 25.0)}
# L-BFGS-B stops when a step improves the log posterior by less than this share of its value (about
# 1e-3 at the emulator's ~700). Against scipy's default (2.2e-9): K-fold RMSE within 0.01 m/s, fits
# 30% faster (docs/emulator.md "Speed")
FIT_TOLERANCE = 1e-6


def correlation(a: np.ndarray, b: np.ndarray, beta: np.ndarray, family: str = "gaussian") -> np.ndarray:
    """Correlation matrix between the rows of a and b."""
    return cross_correlation(np.ascontiguousarray(a, dtype=float), np.ascontiguousarray(b, dtype=float),
                             np.asarray(beta, dtype=float), family_code(family))


@dataclass
class Hyper:
    """Hyperparameters of one GP (the constant mean is profiled, not optimised)."""

    lambda_w: float
    beta: np.ndarray
    lambda_n: float
    mean: float = 0.0

    def packed(self) -> np.ndarray:
        """The optimiser's coordinates (log lambda_w, log beta_k, log lambda_n)."""
        return np.log(np.concatenate([[self.lambda_w], self.beta, [self.lambda_n]]))

    @classmethod
    def unpack(cls, phi: np.ndarray, mean: float = 0.0) -> Hyper:
        return cls(float(np.exp(phi[0])), np.exp(phi[1:-1]), float(np.exp(phi[-1])), float(mean))


def log_prior(phi: np.ndarray) -> tuple[float, np.ndarray]:
    """Log prior density in log coordinates (Jacobian included) and its gradient."""
    a_w, b_w = LAMBDA_W_PRIOR
    a_r, b_r = RHO_PRIOR
    a_n, b_n = LAMBDA_N_PRIOR
    lam_w, beta, lam_n = np.exp(phi[0]), np.exp(phi[1:-1]), np.exp(phi[-1])
    rho = np.exp(-beta / 4.0)
    # Gamma in log coordinates: a log(lambda) - b lambda
    lp = a_w * phi[0] - b_w * lam_w + a_n * phi[-1] - b_n * lam_n
    # Beta(a, b) on rho, rho = exp(-beta/4), coordinate log beta: Jacobian rho * beta / 4
    lp += np.sum((a_r - 1.0) * np.log(rho) + (b_r - 1.0) * np.log1p(-rho) + np.log(rho * beta / 4.0))
    grad = np.empty_like(phi)
    grad[0] = a_w - b_w * lam_w
    grad[-1] = a_n - b_n * lam_n
    # d/dlog(beta) of [a_r * log(rho) + (b_r - 1) log(1 - rho) + log(beta)] with log(rho) = -beta/4
    grad[1:-1] = -a_r * beta / 4.0 + (b_r - 1.0) * (rho * beta / 4.0) / (1.0 - rho) + 1.0
    return float(lp), grad


def _inverse_from_cholesky(lower: np.ndarray) -> np.ndarray:
    """Symmetric inverse from a lower Cholesky factor (LAPACK potri: half the work of two solves)."""
    inv, info = linalg.lapack.dpotri(lower, lower=1)
    if info != 0:
        raise linalg.LinAlgError(f"potri failed ({info})")
    return np.tril(inv) + np.tril(inv, -1).T


def _gls_mean(factor, y: np.ndarray) -> float:
    """Generalised-least-squares constant mean 1'K^-1 y / 1'K^-1 1."""
    k_inv_1 = linalg.cho_solve(factor, np.ones(len(y)), check_finite=False)
    return float(k_inv_1 @ y / k_inv_1.sum())


def neg_log_posterior(phi: np.ndarray, x: np.ndarray, y: np.ndarray, family: str, jitter: float,
                      fit_mean: bool) -> tuple[float, np.ndarray]:
    """Negative log marginal posterior of the hyperparameters and its analytic gradient.

    The correlation matrix, its slope and the gradient's sums over pairs are numba kernels
    (`shockcal.emulator.correlation`). With `fit_mean` the constant mean is profiled out at its GLS estimate
    (no extra gradient term there).
    """
    hyp = Hyper.unpack(phi)
    n = len(y)
    corr, slope = correlation_and_slope(x, hyp.beta, family_code(family))
    cov = corr / hyp.lambda_w
    cov.flat[::n + 1] += 1.0 / hyp.lambda_n + jitter
    try:
        factor = linalg.cho_factor(cov, lower=True, check_finite=False)
    except linalg.LinAlgError:
        return np.inf, np.zeros_like(phi)
    resid = y - _gls_mean(factor, y) if fit_mean else y
    alpha = linalg.cho_solve(factor, resid, check_finite=False)
    inv_lower, info = linalg.lapack.dpotri(factor[0], lower=1)
    if info != 0:
        return np.inf, np.zeros_like(phi)
    logdet = 2.0 * np.log(np.diag(factor[0])).sum()
    nll = 0.5 * resid @ alpha + 0.5 * logdet
    # d nll / d cov = W / 2 with W = K^-1 - alpha alpha'
    w_corr, pair_sums, w_trace = gradient_sums(inv_lower, alpha, corr, slope, x)
    grad = np.empty_like(phi)
    grad[0] = -0.5 * w_corr / hyp.lambda_w
    grad[1:-1] = 0.5 * hyp.beta * pair_sums / hyp.lambda_w
    grad[-1] = -0.5 * w_trace / hyp.lambda_n
    lp, lp_grad = log_prior(phi)
    return nll - lp, grad - lp_grad


class GaussianProcess:
    """A GP conditioned on (x, y): prediction, closed-form leave-one-out."""

    def __init__(self, x: np.ndarray, y: np.ndarray, hyper: Hyper, jitter: float = 1e-8, family: str = "gaussian"):
        self.x = np.asarray(x, dtype=float)
        self.y = np.asarray(y, dtype=float)
        self.hyper, self.jitter, self.family = hyper, jitter, family
        cov = self.prior_cov(self.x, self.x)
        cov.flat[::len(self.y) + 1] += 1.0 / hyper.lambda_n + jitter
        self.factor = linalg.cho_factor(cov, lower=True)
        self.alpha = linalg.cho_solve(self.factor, self.y - hyper.mean)

    @classmethod
    def fit(cls, x, y, n_starts: int = 4, seed: int | np.random.SeedSequence = 0, jitter: float = 1e-8, fit_rows=None,
            family: str = "gaussian", fit_mean: bool = False, start: Hyper | None = None) -> GaussianProcess:
        """MAP hyperparameters (L-BFGS-B from several starts), then condition on all of (x, y).

        `fit_rows` restricts the hyperparameter fit to a subset of rows (for speed on large
        designs); the returned process is conditioned on every row. `start` (hyperparameters of a
        related fit, e.g. on all rows when refitting a fold) is the one start, in place of `n_starts`.
        """
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        xs, ys = (x, y) if fit_rows is None else (x[fit_rows], y[fit_rows])
        dim = x.shape[1]
        rng = np.random.default_rng(seed)
        bounds = [LOG_BOUNDS["lambda_w"]] + [LOG_BOUNDS["beta"]] * dim + [LOG_BOUNDS["lambda_n"]]
        starts = [np.concatenate([[0.0], np.full(dim, np.log(b)), [np.log(1e3)]]) for b in (1.0, 5.0)]
        while len(starts) < n_starts:
            starts.append(np.concatenate([[rng.normal(0, 0.5)], rng.uniform(np.log(0.05), np.log(20.0), dim),
                                          [rng.uniform(3.0, 12.0)]]))
        if start is not None:
            starts, n_starts = [np.clip(start.packed(), *np.array(bounds).T)], 1
        best = None
        for phi0 in starts[:max(n_starts, 1)]:
            res = optimize.minimize(neg_log_posterior, phi0, args=(xs, ys, family, jitter, fit_mean), jac=True,
                                    method="L-BFGS-B", bounds=bounds, options={"ftol": FIT_TOLERANCE})
            if best is None or res.fun < best.fun:
                best = res
        hyper = Hyper.unpack(best.x)
        if fit_mean:
            cov = correlation(x, x, hyper.beta, family) / hyper.lambda_w
            cov.flat[::len(y) + 1] += 1.0 / hyper.lambda_n + jitter
            hyper.mean = _gls_mean(linalg.cho_factor(cov, lower=True), y)
        return cls(x, y, hyper, jitter, family)

    def prior_cov(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        return correlation(a, b, self.hyper.beta, self.family) / self.hyper.lambda_w

    def predict(self, x_new: np.ndarray, include_nugget: bool = True) -> tuple[np.ndarray, np.ndarray]:
        """Predictive mean and variance at `x_new` (the nugget is part of a new observation)."""
        return self.predict_from_cross_cov(self.prior_cov(np.asarray(x_new, dtype=float), self.x), include_nugget)

    def predict_from_cross_cov(self, k: np.ndarray, include_nugget: bool = True) -> tuple[np.ndarray, np.ndarray]:
        """`predict` given k = prior_cov(x_new, x_train) (so that callers can build k on other threads).
        The mean is an einsum, not a BLAS product: with two BLAS threads, a matrix-vector product
        just before the triangular solve made the solve twice as slow (measured)."""
        mean = self.hyper.mean + np.einsum("ij,j->i", k, self.alpha)
        v = linalg.solve_triangular(self.factor[0], k.T, lower=True, check_finite=False)
        var = 1.0 / self.hyper.lambda_w - np.einsum("ij,ij->j", v, v)
        if include_nugget:
            var = var + 1.0 / self.hyper.lambda_n + self.jitter
        return mean, np.maximum(var, 0.0)

    def predict_joint(self, x_new: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Predictive mean and full covariance (no nugget) at `x_new`: for drawing smooth functions."""
        x_new = np.asarray(x_new, dtype=float)
        k = self.prior_cov(x_new, self.x)
        return self.hyper.mean + k @ self.alpha, self.prior_cov(x_new, x_new) - k @ self.inv_cov @ k.T

    @cached_property
    def inv_cov(self) -> np.ndarray:
        """K^-1, built on first use (only LOO and joint prediction need it, not the folds' refits or
        a loaded emulator's predictions)."""
        return _inverse_from_cholesky(self.factor[0])

    def loo(self) -> tuple[np.ndarray, np.ndarray]:
        """Leave-one-out predictive mean and variance in closed form (hyperparameters fixed)."""
        diag = np.diag(self.inv_cov)
        return self.y - self.alpha / diag, 1.0 / diag
