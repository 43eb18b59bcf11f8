"""The emulator's error variance over the box: a smooth multiplier of each output's predictive variance.

A K-fold's held-out errors, divided by the fold models' own predictive sd, give z values whose
variance is not the same everywhere: it grows near faces of the box where the emulator is weak
(FLAG runs 0-499: mean z^2 2.4 in n's lowest fifth against 1.0 in the middle, docs/emulator.md).
`VarianceModel` says

    log Var(z | x) = g(x) + const,   g(x) = sum_k s_k(x_k) + c log(s_raw(x) / s_ref),

per group of outputs: an additive cubic B-spline s_k per scaled input x_k (fixed knots on [0, 1],
scikit-learn's `SplineTransformer`) and a slope c on the log of the emulator's own (uncalibrated)
predictive sd relative to its K-fold median, which makes bands widen where the emulator
extrapolates (it is a smooth function of x too). The coefficients are a ridge regression of the
K-fold's log z^2 (scikit-learn's `RidgeCV`, penalty chosen by its efficient leave-one-out) on those
regressors; each group's target is the mean over its outputs of log z^2 less each output's mean, so
the outputs of a group share g and a group pools their noise (log z^2 of one value has an sd of 2.2).
g is centred on the training rows; the level stays with the emulator's per-output sd factors
(`shockcal.emulator.pcgp`), fitted after g. Cubic B-splines keep g twice differentiable in x, so a calibration
likelihood that uses it stays smooth.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cache

import numpy as np
from sklearn.linear_model import RidgeCV
from sklearn.preprocessing import SplineTransformer

KNOTS = 4                              # knots per input on [0, 1] (6 cubic B-splines per input)
ALPHAS = np.logspace(-2, 4, 13)        # ridge penalties RidgeCV chooses from (leave-one-out)
MIN_Z2 = 1e-12                         # floor of z^2 before its log (an error of exactly 0)


@cache
def _spline(d: int, knots: int) -> SplineTransformer:
    """The cubic B-splines of d inputs, knots fixed on [0, 1] (the fit reads only their number)."""
    grid = np.tile(np.linspace(0.0, 1.0, knots)[:, None], (1, d))
    return SplineTransformer(n_knots=knots, degree=3, knots=grid, extrapolation="constant").fit(grid)


def _basis(x: np.ndarray, knots: int) -> np.ndarray:
    """(N, d (knots + 2)) cubic B-spline basis of scaled inputs x (N, d), constant beyond [0, 1]."""
    return _spline(x.shape[1], knots).transform(x)


@dataclass
class VarianceModel:
    """log variance multipliers g (N, F) of an emulator's outputs over its scaled inputs.

    groups: output columns that share one g (each output in exactly one group).
    coef: (G, d (knots + 2)) spline coefficients per group; sd_slope (G,): the slope c on
    log(raw sd / ref_sd) (the group's mean over its outputs); intercept (G,); ref_sd (F,): each
    output's reference raw sd (the K-fold median, output units).
    """

    groups: list[list[int]]
    coef: np.ndarray
    sd_slope: np.ndarray
    intercept: np.ndarray
    ref_sd: np.ndarray
    knots: int = KNOTS
    alphas: list[float] = field(default_factory=list)     # the penalty chosen per group (a record)

    @classmethod
    def fit(cls, x: np.ndarray, z: np.ndarray, raw_sd: np.ndarray, groups: list[list[int]],
            knots: int = KNOTS) -> VarianceModel:
        """Fit g to held-out z values.

        Args:
            x: scaled inputs (N, d) in [0, 1] of the held-out points.
            z: held-out errors over the predictive sd they were made with (N, F), dimensionless.
            raw_sd: the predicting models' own, uncalibrated sd (N, F), output units.
            groups: output columns sharing one g; every column of z in exactly one group.
            knots: knots per input (cubic B-splines; knots + 2 basis functions per input).
        """
        x, z, raw_sd = (np.asarray(a, dtype=float) for a in (x, z, raw_sd))
        covered = sorted(c for g in groups for c in g)
        if covered != list(range(z.shape[1])):
            raise ValueError(f"variance model: groups {groups} must hold each of the {z.shape[1]} outputs once")
        ref_sd = np.median(raw_sd, axis=0)
        t = np.log(np.maximum(z**2, MIN_Z2))
        t -= t.mean(axis=0)
        basis = _basis(x, knots)
        log_sd = np.log(raw_sd / ref_sd)
        coef, slope, intercept, alphas = [], [], [], []
        for group in groups:
            design = np.column_stack([basis, log_sd[:, group].mean(axis=1)])
            ridge = RidgeCV(alphas=ALPHAS).fit(design, t[:, group].mean(axis=1))
            coef.append(ridge.coef_[:-1])
            slope.append(ridge.coef_[-1])
            intercept.append(ridge.intercept_ - ridge.predict(design).mean())     # g centred on the rows
            alphas.append(float(ridge.alpha_))
        return cls([list(map(int, g)) for g in groups], np.array(coef), np.array(slope), np.array(intercept),
                   ref_sd, knots, alphas)

    def log_variance(self, x: np.ndarray, raw_sd: np.ndarray) -> np.ndarray:
        """g (N, F): the log multiplier of each output's variance at scaled inputs x (N, d), given the
        emulator's raw sd there (N, F), output units."""
        basis = _basis(np.asarray(x, dtype=float), self.knots)
        log_sd = np.log(np.asarray(raw_sd, dtype=float) / self.ref_sd)
        g = np.empty(np.shape(raw_sd))
        for j, group in enumerate(self.groups):
            g[:, group] = (basis @ self.coef[j] + self.sd_slope[j] * log_sd[:, group].mean(axis=1)
                           + self.intercept[j])[:, None]
        return g

    def sd_factors(self, x: np.ndarray, raw_sd: np.ndarray) -> np.ndarray:
        """(N, F) sd multipliers exp(g / 2) at scaled inputs x and raw sd (see `log_variance`)."""
        return np.exp(0.5 * self.log_variance(x, raw_sd))

    def to_arrays(self, prefix: str = "") -> dict:
        return {f"{prefix}variance_coef": self.coef, f"{prefix}variance_sd_slope": self.sd_slope,
                f"{prefix}variance_intercept": self.intercept, f"{prefix}variance_ref_sd": self.ref_sd}

    def to_json(self) -> dict:
        return {"groups": self.groups, "knots": self.knots, "alphas": self.alphas}

    @classmethod
    def from_saved(cls, meta: dict, arrays, prefix: str = "") -> VarianceModel:
        return cls(meta["groups"], *(np.asarray(arrays[f"{prefix}variance_{k}"])
                                     for k in ("coef", "sd_slope", "intercept", "ref_sd")),
                   int(meta["knots"]), list(meta["alphas"]))
