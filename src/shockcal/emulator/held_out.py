"""Held-out predictions of the PC-GP emulator (`HeldOut`) and the sd calibration read from them: the
factors that make K-fold 90% bands hold 90% (constant per output, or over a smooth variance model,
`shockcal.emulator.variance_model`), in the usual regime and past a `Switch`, and the nested K-fold that
scales each fold by the calibration of the others (`cross_fitted`). `model` is a fitted
`shockcal.emulator.pcgp.PCGPEmulator`: its training outputs, settings, sd groups and switch weights.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from shockcal.emulator.variance_model import VarianceModel

Z90 = 1.6449                        # half-width of a central 90% normal band, in sd (z_0.95 = 1.64485 to 4 digits)
SWITCH_MIN_RUNS = 30                # held-out values past a switch needed for its own sd factor


@dataclass
class HeldOut:
    """Held-out predictions of a cross-validation scheme: row indices, mean and sd (N, F), and the
    covariance (N, F, F) where the scheme has it (not closed-form LOO)."""

    scheme: str
    rows: np.ndarray
    mean: np.ndarray
    sd: np.ndarray
    cov: np.ndarray | None = None

    def scaled(self, factors: np.ndarray) -> HeldOut:
        """The same predictions with sd (and covariance) scaled by per-row, per-feature factors (N, F)."""
        cov = None if self.cov is None else self.cov * factors[:, :, None] * factors[:, None, :]
        return HeldOut(self.scheme, self.rows, self.mean, self.sd * factors, cov)

    def distances(self, y: np.ndarray) -> tuple[np.ndarray, int]:
        """Squared Mahalanobis distance of each held-out error (y[rows] - mean) under its covariance,
        in the space the covariance spans (a pseudo-inverse: duplicated outputs make it singular),
        and that space's dimension (the covariances' median rank)."""
        err = y[self.rows] - self.mean
        rank = int(np.median(np.linalg.matrix_rank(self.cov, hermitian=True)))
        return np.einsum("ni,nij,nj->n", err, np.linalg.pinv(self.cov, hermitian=True), err), rank


def sd_calibration(model, held: HeldOut, use: np.ndarray) -> tuple[np.ndarray, VarianceModel | None]:
    """The sd calibration from the rows `use` of a held-out set with the fold models' own sd: with
    sd_model "smooth", the variance model g fitted to their z values, then the (2, F) constant
    factors (`sd_factor_quantiles`) of the z values divided by exp(g / 2); with "constant", the factors alone."""
    if model.settings.sd_model != "smooth":
        return sd_factor_quantiles(model, held, use), None
    x, sd = model.x_train[held.rows[use]], held.sd[use]
    variance = VarianceModel.fit(x, (held.mean[use] - model.y_train[held.rows[use]]) / sd, sd, model.sd_groups)
    smooth = np.ones_like(held.sd)
    smooth[use] = variance.sd_factors(x, sd)
    return sd_factor_quantiles(model, held.scaled(smooth), use), variance


def sd_factor_quantiles(model, held: HeldOut, use: np.ndarray) -> np.ndarray:
    """(2, F) sd factors from the rows `use` of a held-out set: per feature, the 90% quantile of
    |error| / sd over 1.645, in the usual regime (row 0) and past a switch (row 1; the usual one
    where fewer than SWITCH_MIN_RUNS held-out values are past it)."""
    z = np.abs(held.mean[use] - model.y_train[held.rows[use]]) / held.sd[use]
    switched = model.switch_weight(held.mean[use]) > 0.5
    factors = np.tile(np.quantile(z, 0.9, axis=0) / Z90, (2, 1))
    for col in np.flatnonzero(switched.sum(0) >= SWITCH_MIN_RUNS):
        past = switched[:, col]
        factors[:, col] = np.quantile(z[~past, col], 0.9) / Z90, np.quantile(z[past, col], 0.9) / Z90
    return factors


def blend_factors(factors: np.ndarray, weight: np.ndarray) -> np.ndarray:
    """(N, F) factors: the usual regime's, moved towards the switched one's by weight (N, F)."""
    return factors[0] + weight * (factors[1] - factors[0])


def cross_fitted(model, held: HeldOut, folds) -> HeldOut:
    """K-fold sd scaled, fold by fold, by the calibration of the other folds (an honest coverage:
    nested, the variance model and the factors never see the fold they scale)."""
    fold_of = np.concatenate([np.full(len(f), j) for j, f in enumerate(folds)])
    factors = np.empty_like(held.sd)
    for j in range(len(folds)):
        here = fold_of == j
        constant, variance = sd_calibration(model, held, ~here)
        factors[here] = blend_factors(constant, model.switch_weight(held.mean[here]))
        if variance is not None:
            factors[here] *= variance.sd_factors(model.x_train[held.rows[here]], held.sd[here])
    return held.scaled(factors)
