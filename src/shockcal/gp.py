"""One Gaussian process with the correlation of Higdon et al. (2008), fitted at its posterior mode.

    cov(w(t), w(t')) = prod_k rho_k^(4 (t_k - t'_k)^2) / lambda_w  +  delta(t, t') / lambda_n

with inputs t in [0, 1]^d. We write rho_k = exp(-beta_k / 4), so the correlation is
exp(-sum_k beta_k (t_k - t'_k)^2). Priors (SPEC section 5): lambda_w ~ Gamma(5, 5),
rho_k ~ Beta(1, 0.1); the nugget precision lambda_n ~ Gamma(3, 0.003) as in GPM/SA. The mode is
found in the coordinates (log lambda_w, log beta_k, log lambda_n), Jacobian included, where the
posterior is proper and smooth (the Beta(1, 0.1) density itself is unbounded at rho = 1).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import linalg, optimize

LAMBDA_W_PRIOR = (5.0, 5.0)         # Gamma(shape, rate) of the marginal precision
RHO_PRIOR = (1.0, 0.1)              # Beta(a, b) of each rho_k
LAMBDA_N_PRIOR = (3.0, 0.003)       # Gamma(shape, rate) of the nugget precision
LOG_BOUNDS = {"lambda_w": (-6.0, 8.0), "beta": (np.log(1e-4), np.log(2e3)), "lambda_n": (0.0, 25.0)}


def squared_distances(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Per-dimension squared differences, shape (len(a), len(b), d)."""
    return (a[:, None, :] - b[None, :, :]) ** 2


def correlation(a: np.ndarray, b: np.ndarray, beta: np.ndarray) -> np.ndarray:
    """exp(-sum_k beta_k (a_k - b_k)^2) via a matrix product (no (n, m, d) temporary)."""
    sa, sb = a * np.sqrt(beta), b * np.sqrt(beta)
    d2 = (sa**2).sum(1)[:, None] + (sb**2).sum(1)[None, :] - 2.0 * sa @ sb.T
    return np.exp(-np.maximum(d2, 0.0))


@dataclass
class Hyper:
    """Hyperparameters of one GP."""

    lambda_w: float
    beta: np.ndarray
    lambda_n: float

    def pack(self) -> np.ndarray:
        return np.concatenate([[np.log(self.lambda_w)], np.log(self.beta), [np.log(self.lambda_n)]])

    @classmethod
    def unpack(cls, phi: np.ndarray) -> "Hyper":
        return cls(float(np.exp(phi[0])), np.exp(phi[1:-1]), float(np.exp(phi[-1])))


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


def neg_log_posterior(phi: np.ndarray, x: np.ndarray, y: np.ndarray, d2: np.ndarray, jitter: float):
    """Negative log marginal posterior of the hyperparameters and its analytic gradient."""
    hyp = Hyper.unpack(phi)
    n = len(y)
    corr = np.exp(-(d2 @ hyp.beta))
    cov = corr / hyp.lambda_w + (1.0 / hyp.lambda_n + jitter) * np.eye(n)
    try:
        factor = linalg.cho_factor(cov, lower=True, check_finite=False)
    except linalg.LinAlgError:
        return np.inf, np.zeros_like(phi)
    alpha = linalg.cho_solve(factor, y, check_finite=False)
    inv = _inverse_from_cholesky(factor[0])
    logdet = 2.0 * np.log(np.diag(factor[0])).sum()
    nll = 0.5 * y @ alpha + 0.5 * logdet
    w = inv - np.outer(alpha, alpha)            # d nll / d cov = w / 2
    wc = w * corr
    grad = np.empty_like(phi)
    grad[0] = -0.5 * wc.sum() / hyp.lambda_w
    grad[1:-1] = -0.5 * hyp.beta * (wc.ravel() @ d2.reshape(n * n, -1)) / hyp.lambda_w
    grad[-1] = -0.5 * np.trace(w) / hyp.lambda_n
    lp, lp_grad = log_prior(phi)
    return nll - lp, grad - lp_grad


class GaussianProcess:
    """A zero-mean GP conditioned on (x, y): prediction, closed-form leave-one-out."""

    def __init__(self, x: np.ndarray, y: np.ndarray, hyper: Hyper, jitter: float = 1e-8):
        self.x = np.asarray(x, dtype=float)
        self.y = np.asarray(y, dtype=float)
        self.hyper = hyper
        self.jitter = jitter
        cov = self.prior_cov(self.x, self.x) + (1.0 / hyper.lambda_n + jitter) * np.eye(len(y))
        factor = linalg.cho_factor(cov, lower=True)
        self.alpha = linalg.cho_solve(factor, self.y)
        self.inv_cov = _inverse_from_cholesky(factor[0])

    @classmethod
    def fit(cls, x, y, n_starts: int = 4, seed: int = 0, jitter: float = 1e-8, fit_rows=None) -> "GaussianProcess":
        """MAP hyperparameters (L-BFGS-B from several starts), then condition on all of (x, y).

        `fit_rows` restricts the hyperparameter fit to a subset of rows (for speed on large
        designs); the returned process is conditioned on every row.
        """
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        xs, ys = (x, y) if fit_rows is None else (x[fit_rows], y[fit_rows])
        d2 = squared_distances(xs, xs)
        rng = np.random.default_rng(seed)
        dim = x.shape[1]
        bounds = [LOG_BOUNDS["lambda_w"]] + [LOG_BOUNDS["beta"]] * dim + [LOG_BOUNDS["lambda_n"]]
        starts = [np.concatenate([[0.0], np.full(dim, np.log(b)), [np.log(1e3)]]) for b in (1.0, 5.0)]
        while len(starts) < n_starts:
            starts.append(np.concatenate([[rng.normal(0, 0.5)], rng.uniform(np.log(0.05), np.log(20.0), dim),
                                          [rng.uniform(3.0, 12.0)]]))
        best = None
        for phi0 in starts[:max(n_starts, 1)]:
            res = optimize.minimize(neg_log_posterior, phi0, args=(xs, ys, d2, jitter), jac=True,
                                    method="L-BFGS-B", bounds=bounds)
            if best is None or res.fun < best.fun:
                best = res
        return cls(x, y, Hyper.unpack(best.x), jitter)

    def prior_cov(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        return correlation(a, b, self.hyper.beta) / self.hyper.lambda_w

    def predict(self, x_new: np.ndarray, include_nugget: bool = True) -> tuple[np.ndarray, np.ndarray]:
        """Predictive mean and variance at `x_new` (the nugget is part of a new observation)."""
        k = self.prior_cov(np.asarray(x_new, dtype=float), self.x)
        mean = k @ self.alpha
        var = 1.0 / self.hyper.lambda_w - np.einsum("ij,ij->i", k @ self.inv_cov, k)
        if include_nugget:
            var = var + 1.0 / self.hyper.lambda_n + self.jitter
        return mean, np.maximum(var, 0.0)

    def predict_joint(self, x_new: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Predictive mean and full covariance (no nugget) at `x_new`: for drawing smooth functions."""
        x_new = np.asarray(x_new, dtype=float)
        k = self.prior_cov(x_new, self.x)
        return k @ self.alpha, self.prior_cov(x_new, x_new) - k @ self.inv_cov @ k.T

    def loo(self) -> tuple[np.ndarray, np.ndarray]:
        """Leave-one-out predictive mean and variance in closed form (hyperparameters fixed)."""
        diag = np.diag(self.inv_cov)
        return self.y - self.alpha / diag, 1.0 / diag
