"""The emulator's error distribution: a multivariate Student t, the Gaussian as its dof -> inf.

An emulator reports a covariance C(theta) per point, each feature's sd scaled so that K-fold 90%
bands hold 90% of held-out runs. Its errors on runs it never saw are heavier-tailed than a Gaussian
with that covariance (docs/emulator.md, "Error tails"): the Mahalanobis distances of the K-fold
errors put 24% of runs beyond chi-square's 90% point. `ErrorModel` says the error is
t_dof(0, scale * C), `dof` and `scale` fitted by maximum likelihood to those distances
(d^2 / (F scale) ~ F-distribution(F, dof); scipy's `f.fit`); one model per emulator, never per run.

In the calibration likelihood the observation noise N(0, Sigma_y / lambda_y) is added to the
t's scale matrix: y - eta ~ t_dof(0, scale C + Sigma_y / lambda_y). This is exact when the noise
is negligible or proportional to C; otherwise it gives the noise the same tail (lambda_y's Gamma(5, 5)
prior already makes the noise t-like, with 10 dof).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import stats
from scipy.special import gammaln

FIT_MAX_DOF = 1e4     # dof fitted above this: the errors are Gaussian for every purpose here


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

    def log_density(self, resid: np.ndarray, emulator_cov: np.ndarray, noise_cov: np.ndarray | None = None
                    ) -> np.ndarray:
        """log t_dof(resid; 0, scale * emulator_cov + noise_cov) for a batch (N, F), (N, F, F);
        NaN where that matrix is not positive definite."""
        cov = self.scale * emulator_cov if noise_cov is None else self.scale * emulator_cov + noise_cov
        return self._log_density(resid, cov)

    def _log_density(self, resid: np.ndarray, cov: np.ndarray) -> np.ndarray:
        try:
            chol = np.linalg.cholesky(cov)
        except np.linalg.LinAlgError:      # locate the bad rows one by one
            return np.array([self._log_density(r[None], c[None])[0] if np.all(np.linalg.eigvalsh(c) > 0)
                             else np.nan for r, c in zip(resid, cov)])
        z = np.linalg.solve(chol, resid[..., None])[..., 0]
        d2, f = np.sum(z**2, axis=1), resid.shape[1]
        log_det = 2.0 * np.log(np.diagonal(chol, axis1=1, axis2=2)).sum(axis=1)
        if np.isinf(self.dof):
            return -0.5 * (d2 + log_det + f * np.log(2 * np.pi))
        nu = self.dof
        return (gammaln(0.5 * (nu + f)) - gammaln(0.5 * nu) - 0.5 * f * np.log(nu * np.pi) - 0.5 * log_det
                - 0.5 * (nu + f) * np.log1p(d2 / nu))

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
