"""The emulator's error distribution: a multivariate Student t, the Gaussian as its dof -> inf.

An emulator reports a covariance C(theta) per point, each feature's sd scaled so that K-fold 90%
bands hold 90% of held-out runs. Its errors on runs it never saw are heavier-tailed than a Gaussian
with that covariance (docs/emulator.md, "Error tails"): the Mahalanobis distances of the K-fold
errors put 24% of runs beyond chi-square's 90% point. `ErrorModel` says the error is
t_dof(0, scale * C), `dof` and `scale` fitted by maximum likelihood to those distances
(d^2 / (F scale) ~ F-distribution(F, dof); scipy's `f.fit`); one model per emulator, never per run.

In the calibration likelihood the observation noise N(0, Sigma_y / lambda_y) is added to the
emulator's error, exactly: the t is a Gaussian scale mixture, error | w ~ N(0, scale C / w) with
w ~ Gamma(dof / 2, rate dof / 2), so

    p(r) = integral over w of N(r; 0, scale C / w + Sigma_y / lambda_y) Gamma(w) dw.

One eigendecomposition per point makes the integrand O(F) per w (`_mixture_log_density`); the
integral is a trapezoid rule in log w (`log_w_grid`), within 1e-8 of adaptive quadrature for dof
1.5-1000 and residuals 0.3-100 times their sd (tests/test_error_model.py).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import stats
from scipy.special import gammaln, logsumexp

FIT_MAX_DOF = 1000.0          # dof fitted above this: Gaussian for every purpose here
LOG_W_RANGE = (-30.0, 8.0)    # w from 1e-13 (far outliers) to 3000
POINTS_PER_BLOCK = 2000       # memory: points x grid nodes per block


@dataclass(frozen=True)
class ErrorModel:
    """Error ~ t_dof(0, scale * C) for an emulator covariance C; dof = inf is N(0, scale * C)."""

    dof: float = np.inf
    scale: float = 1.0

    @classmethod
    def fit(cls, distances: np.ndarray, n_features: int) -> ErrorModel:
        """Maximum-likelihood (dof, scale) from squared Mahalanobis distances d^2 = e' C^-1 e of
        held-out errors e under their predicted covariances C."""
        d2 = np.asarray(distances, dtype=float)
        if d2.ndim != 1 or len(d2) < 10 or not np.all(np.isfinite(d2) & (d2 > 0)):
            raise ValueError(f"error model: {len(d2)} distances, at least 10 finite positive ones are needed")
        _, dof, _, f_scale = stats.f.fit(d2, fdfn=n_features, floc=0)
        return cls(np.inf if dof > FIT_MAX_DOF else float(dof), float(f_scale / n_features))

    def log_density(self, resid: np.ndarray, emulator_cov: np.ndarray, noise_var: np.ndarray | None = None
                    ) -> np.ndarray:
        """log p(resid) for resid = error + noise, a batch (N, F), emulator covariance (N, F, F) and
        independent Gaussian noise of variances noise_var (N, F) (None: no noise, the t itself);
        NaN where the emulator covariance is not positive semi-definite or not finite."""
        if noise_var is None or np.isinf(self.dof):
            cov = self.scale * emulator_cov
            if noise_var is not None:
                cov = cov + noise_var[:, :, None] * np.eye(resid.shape[1])
            return _closed_form(resid, cov, self.dof)
        out = np.full(len(resid), np.nan)
        ok = np.isfinite(resid).all(1) & np.isfinite(emulator_cov).all((1, 2)) & np.isfinite(noise_var).all(1)
        rows = np.flatnonzero(ok)
        for block in np.array_split(rows, -(-len(rows) // POINTS_PER_BLOCK)):
            out[block] = self._mixture_log_density(resid[block], emulator_cov[block], noise_var[block])
        return out

    def _mixture_log_density(self, resid, emulator_cov, noise_var) -> np.ndarray:
        """The scale-mixture integral: with D = noise sd^-1 and scale D C D = Q diag(e) Q', the
        covariance scale C / w + noise is D^-1 Q diag(e / w + 1) Q' D^-1, so the Gaussian's
        distance and log-determinant at w are sums over F eigenvalues."""
        inv_sd = 1.0 / np.sqrt(noise_var)
        e, q = np.linalg.eigh(self.scale * emulator_cov * inv_sd[:, :, None] * inv_sd[:, None, :])
        rho2 = np.einsum("nij,ni->nj", q, resid * inv_sd) ** 2
        log_w, step = log_w_grid(self.dof, resid.shape[1])
        w = np.exp(log_w)
        d2, log_det = np.zeros((len(resid), len(w))), np.zeros((len(resid), len(w)))
        for j in range(resid.shape[1]):
            a = np.clip(e[:, j:j + 1], 0.0, None) / w + 1.0
            d2 += rho2[:, j:j + 1] / a
            log_det += np.log(a)
        half_nu = 0.5 * self.dof
        log_prior = half_nu * np.log(half_nu) - gammaln(half_nu) + half_nu * (log_w - w)   # of log w
        log_gauss = -0.5 * (d2 + log_det + np.log(noise_var).sum(1, keepdims=True)
                            + resid.shape[1] * np.log(2 * np.pi))
        value = logsumexp(log_gauss + log_prior, axis=1) + np.log(step)
        not_psd = e[:, 0] < -1e-9 * np.abs(e[:, -1])
        return np.where(not_psd, np.nan, value)

    def sample(self, mean: np.ndarray, emulator_cov: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        """One draw of mean + error (F,) for an emulator mean (F,) and covariance (F, F)."""
        if np.isinf(self.dof):
            return rng.multivariate_normal(mean, self.scale * emulator_cov)
        return stats.multivariate_t.rvs(mean, self.scale * emulator_cov, df=self.dof, random_state=rng)

    def to_json(self) -> dict:
        return {"dof": None if np.isinf(self.dof) else self.dof, "scale": self.scale}

    @classmethod
    def from_json(cls, d: dict) -> ErrorModel:
        return cls(np.inf if d["dof"] is None else float(d["dof"]), float(d["scale"]))


def _closed_form(resid: np.ndarray, cov: np.ndarray, dof: float) -> np.ndarray:
    """log t_dof(resid; 0, cov) (Gaussian for dof = inf), a batch; NaN where cov is not positive definite."""
    try:
        chol = np.linalg.cholesky(cov)
    except np.linalg.LinAlgError:      # locate the bad rows one by one
        return np.array([_closed_form(r[None], c[None], dof)[0] if np.all(np.linalg.eigvalsh(c) > 0) else np.nan
                         for r, c in zip(resid, cov)])
    z = np.linalg.solve(chol, resid[..., None])[..., 0]
    d2, f = np.sum(z**2, axis=1), resid.shape[1]
    log_det = 2.0 * np.log(np.diagonal(chol, axis1=1, axis2=2)).sum(axis=1)
    if np.isinf(dof):
        return -0.5 * (d2 + log_det + f * np.log(2 * np.pi))
    return (gammaln(0.5 * (dof + f)) - gammaln(0.5 * dof) - 0.5 * f * np.log(dof * np.pi) - 0.5 * log_det
            - 0.5 * (dof + f) * np.log1p(d2 / dof))


def log_w_grid(dof: float, n_features: int) -> tuple[np.ndarray, float]:
    """Trapezoid nodes in log w and their step. Given a residual, log w has a density of width at
    least sqrt(2 / (dof + F)) (a Gamma of shape (dof + F) / 2 when the noise is negligible, wider
    otherwise); a step of half that puts the trapezoid rule's error below exp(-2 pi^2 4) = 1e-34."""
    step = 0.5 * np.sqrt(2.0 / (dof + n_features))
    return np.arange(LOG_W_RANGE[0], LOG_W_RANGE[1] + step / 2, step), step
