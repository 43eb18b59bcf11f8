"""The posterior density of a calibration: a predictive model, measured features, a prior box (SPEC sections 5-6).

For the shots calibrated together, the measured features y (m/s, four per shot) are modelled as

    y = eta(theta) + e + eps,   e ~ t_nu(0, s C_eta(theta)),   eps ~ N(0, Sigma_y / lambda_y),

eta and C_eta the emulator's predictive mean and covariance, (nu, s) its error model (a Student t
fitted to its K-fold errors, `shockcal.emulator.error_model`; nu = inf, s = 1 is the paper's Gaussian), one
e per emulator block (their errors are independent), Sigma_y diagonal with variance
(`observed.sd_fraction` y)^2 + r^2 for each measured feature y (1%, and r the extractor's read-out sd on
the record, `readout_sd_<feature>` in the observed table), lambda_y ~ Gamma(5, 5), theta uniform on the
prior box. The emulator's hyperparameters are fixed at their fitted mode (modular Bayes; see
docs/calibration.md). A point is (theta in native units, lambda_y); both priors are reached from the
unit cube (`Problem.prior_transform`).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy import stats

from shockcal.emulator.error_model import ErrorModel
from shockcal.errors import InputError
from shockcal.inference.discrepancy import Discrepancy, from_setting
from shockcal.plausibility import outside_box

LAMBDA_Y = "lambda_y"          # the observation-precision scale: its column in draws, designs and summaries
LAMBDA_Y_PRIOR = (5.0, 5.0)   # Gamma(shape, rate) of the observation-precision scale


@dataclass
class Problem:
    """Everything the posterior density needs: a predictive model, observed features, prior box.

    `predict` maps theta (N, d) in native units to the predictive mean (N, F) and covariance
    (N, F, F) of the features, m/s: any emulator (`PCGPEmulator.predict` from a notebook, or a
    study's `Emulator` through `Problem.for_shots`). Points are (theta, lambda_y). `prior_transform`
    and `log_likelihood` are the pair a nested or SMC sampler takes (vectorised over a batch of
    points); `log_posterior` is the same density for MCMC in (theta, log lambda_y).
    `error_groups`: (feature columns, ErrorModel) pairs covering the features once; default, one
    Gaussian over all of them.
    """

    predict: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]
    observed: np.ndarray      # (F,) m/s
    obs_sd: np.ndarray        # (F,) m/s
    names: list[str]          # calibrated inputs, native units
    lower: np.ndarray
    upper: np.ndarray
    label: str = "calibration"
    error_groups: list[tuple[np.ndarray, ErrorModel]] | None = None
    discrepancy: Discrepancy | None = None   # None: `calibration.discrepancy: none`, points (theta, lambda_y)

    @classmethod
    def from_emulator(cls, emulator, *, observed, sd_fraction: float = 0.01, names=None, label: str = "calibration"
                      ) -> Problem:
        """The problem of an array-level emulator (`PCGPEmulator`), its prior box and error model.

        Args:
            emulator: a fitted `PCGPEmulator` (its box is the prior box, its error model the likelihood's).
            observed: measured features (F,), m/s, in the emulator's output order.
            sd_fraction: observation sd as a fraction of each measured feature (0.01: 1%).
            names: the inputs' names (default the emulator's `input_names`).
            label: names the problem in messages.
        """
        y = np.asarray(observed, dtype=float)
        names = list(emulator.input_names if names is None else names)
        return cls(emulator.predict, y, sd_fraction * np.abs(y), names, np.asarray(emulator.lower, dtype=float),
                   np.asarray(emulator.upper, dtype=float), label, emulator.error_groups())

    @classmethod
    def for_shots(cls, emulator, shots, observed_table: pd.DataFrame, sd_fraction: float, source: str = "observed",
                  bounds: Mapping[str, tuple[float, float]] | None = None, units: Mapping[str, str] | None = None,
                  discrepancy="none") -> Problem:
        """The study's problem: the inputs `shots` need, their box, and their measured features.

        Args:
            emulator: the study's `Emulator` (design inputs in native units).
            shots: the shots calibrated together (one: a single-shot calibration; a shot twice is an error).
            observed_table: measured features, one row per shot (m/s); a column `readout_sd_<feature>`
                (m/s, the extractor's read-out sd on the record: `shockcal observed`) adds to the
                feature's observation sd in quadrature (absent: 0).
            sd_fraction: observation sd as a fraction of each measured feature.
            source: names the table in errors.
            bounds: the prior box by input (native units; the study config's `inputs`), or None for the
                emulator's box. It must lie inside the box the emulator was fitted on (`prior_box`).
            units: each input's unit, for messages.
            discrepancy: `calibration.discrepancy` ("none", or {kind: feature_kind, sd_fraction_prior}:
                `shockcal.inference.discrepancy`).
        """
        shots = list(shots)
        twice = sorted({shot for shot in shots if shots.count(shot) > 1})
        if twice:
            raise InputError(f"shots {shots}: {', '.join(twice)} listed more than once; name each shot once")
        names = emulator.required_inputs(shots)
        lower, upper = emulator.input_bounds(names)
        if bounds is not None:
            lower, upper = prior_box(names, bounds, lower, upper, f"calibration of {'+'.join(shots)}", units or {})
        y = observed_vector(observed_table, shots, emulator.feature_names, source)
        readout = readout_vector(observed_table, shots, emulator.feature_names, source)

        def predict(theta):
            return emulator.predict(dict(zip(names, theta.T)), list(shots))

        return cls(predict, y, np.hypot(sd_fraction * np.abs(y), readout), names, np.asarray(lower), np.asarray(upper),
                   "+".join(shots), emulator.error_groups(shots),
                   from_setting(discrepancy, emulator.feature_names, len(shots)))

    @property
    def ndim(self) -> int:
        return len(self.names) + 1 + len(self.discrepancy_names)

    @property
    def discrepancy_names(self) -> list[str]:
        """The discrepancy's sampled parameters (after lambda_y in a point), none without one."""
        return [] if self.discrepancy is None else self.discrepancy.names

    def prior_transform(self, u: np.ndarray) -> np.ndarray:
        """Unit cube (N, ndim) -> (theta uniform on the box, lambda_y ~ Gamma(5, 5), the discrepancy's
        parameters from their priors, `shockcal.inference.discrepancy`)."""
        u = np.atleast_2d(u)
        shape, rate = LAMBDA_Y_PRIOR
        d = len(self.names)
        theta = self.lower + u[:, :d] * (self.upper - self.lower)
        point = np.column_stack([theta, stats.gamma.ppf(u[:, d], shape, scale=1.0 / rate)])
        if self.discrepancy is None:
            return point
        return np.column_stack([point, self.discrepancy.prior_transform(u[:, d + 1:])])

    def cube_power(self, powers: Mapping[str, float], others: str = "error") -> np.ndarray:
        """`nested_sample`'s per-coordinate unit-cube power from powers of named inputs (1 for the
        others and lambda_y). A name this problem does not calibrate is an error, or with
        `others="ignore"` skipped (a study's powers in a single-shot calibration: 104S has no Delta2)."""
        unknown = sorted(set(powers) - set(self.names))
        if unknown and others != "ignore":
            raise InputError(f"{self.label}: calibration.cube_power names {unknown}, not among the calibrated "
                             f"inputs {self.names}")
        return np.array([float(powers.get(name, 1.0)) for name in self.names] + [1.0] * (1 + len(self.discrepancy_names)))

    def log_likelihood(self, points: np.ndarray) -> np.ndarray:
        """Log-likelihood of the observed features at points (N, d + 1) = (theta, lambda_y)
        inside the box, normalising constants included (so the evidence is a true marginal likelihood).
        A non-finite value is an error naming the point: it means the emulator is broken there."""
        points = np.atleast_2d(points)
        if self.discrepancy is not None:
            value = self._log_likelihood_with_discrepancy(points)
        else:
            theta, lam = points[:, :-1], points[:, -1]
            mean, cov = self.predict(theta)
            resid = self.observed - mean
            groups = self.error_groups or [(np.arange(len(self.observed)), ErrorModel())]
            value = np.zeros(len(points))
            for cols, error in groups:
                noise_var = self.obs_sd[cols] ** 2 / lam[:, None]
                value += error.log_density(resid[:, cols], cov[:, cols[:, None], cols[None, :]], noise_var)
        bad = ~np.isfinite(value)
        if bad.any():
            point = dict(zip([*self.names, LAMBDA_Y, *self.discrepancy_names], points[np.argmax(bad)].tolist()))
            raise InputError(f"{self.label}: the log-likelihood is not finite at {point} "
                             "(the emulator's prediction or covariance is invalid there)")
        return value

    def _log_likelihood_with_discrepancy(self, points: np.ndarray) -> np.ndarray:
        """One joint Gaussian over all features: the blocks' emulator covariances (each scaled by its
        error model's s) block-diagonal, plus Sigma_delta (correlated across shots, so across blocks),
        plus the noise. A Student-t block cannot share a Gaussian across blocks: refused."""
        d = len(self.names)
        theta, lam, phi = points[:, :d], points[:, d], points[:, d + 1:]
        mean, cov = self.predict(theta)
        groups = self.error_groups or [(np.arange(len(self.observed)), ErrorModel())]
        total = self.discrepancy.covariance(phi, self.observed) + \
            (self.obs_sd ** 2 / lam[:, None])[:, :, None] * np.eye(len(self.observed))
        for cols, error in groups:
            if np.isfinite(error.dof):
                raise InputError(f"{self.label}: calibration.discrepancy needs Gaussian emulator errors, and a block "
                                 f"has a Student t (dof {error.dof:g}); set the emulator's error model to gaussian "
                                 "or calibration.discrepancy: none")
            total[:, cols[:, None], cols[None, :]] += error.scale * cov[:, cols[:, None], cols[None, :]]
        return ErrorModel().log_density(self.observed - mean, total)

    def hydrocode_log_likelihood(self, features: np.ndarray, lambda_y: np.ndarray) -> np.ndarray:
        """Log-likelihood of the observed features when the predicted features are known exactly (a
        hydrocode run's, (N, F) m/s, in the problem's feature order) at lambda_y (N,): the noise of
        `log_likelihood` (obs_sd^2 / lambda_y), without the emulator's share. NaN where a feature is NaN."""
        features, lam = np.atleast_2d(np.asarray(features, dtype=float)), np.asarray(lambda_y, dtype=float)
        noise_var = self.obs_sd ** 2 / lam[:, None]
        return ErrorModel().log_density(self.observed - features, np.zeros((*features.shape, features.shape[1])),
                                        noise_var)

    def log_posterior(self, x: np.ndarray) -> np.ndarray:
        """Log posterior (up to a constant) at x (N, d + 1) = (theta, log lambda_y); -inf outside the
        box. The Gamma prior of lambda_y and the Jacobian of the log are included."""
        x = np.atleast_2d(x)
        if self.discrepancy is not None:
            raise InputError(f"{self.label}: calibration.discrepancy is sampled by nested sampling only (nautilus); "
                             "log_posterior covers (theta, log lambda_y)")
        out = np.full(len(x), -np.inf)
        inside = np.all((x[:, :-1] >= self.lower) & (x[:, :-1] <= self.upper), axis=1) & np.isfinite(x[:, -1])
        if inside.any():
            log_lam = x[inside, -1]
            lam = np.exp(log_lam)
            shape, rate = LAMBDA_Y_PRIOR
            out[inside] = self.log_likelihood(np.column_stack([x[inside, :-1], lam])) + shape * log_lam - rate * lam
        return out


def prior_box(names, bounds: Mapping[str, tuple[float, float]], emulator_lower, emulator_upper, label: str,
              units: Mapping[str, str]) -> tuple[np.ndarray, np.ndarray]:
    """The prior box of `names` from `bounds` (the study's `inputs`, native units), checked against the
    box the emulator was fitted on (`emulator_lower`, `emulator_upper`).

    A prior box inside the emulator's is calibrated on as it is (a narrower prior is a statement about
    the inputs, and the emulator is valid on it); one reaching outside it would ask the emulator to
    extrapolate, and is an InputError naming the input and both boxes. An input the box lacks is an
    InputError too."""
    lower, upper = [], []
    for name, low, high in zip(names, emulator_lower, emulator_upper):
        if name not in bounds:
            raise InputError(f"{label}: the prior box has no input {name}, which the emulator's calibration needs")
        lo, hi = (float(b) for b in bounds[name])
        if outside_box([lo, hi], low, high).any():
            unit = "" if units.get(name, "-") == "-" else f" {units[name]}"
            raise InputError(f"{label}: the prior box inputs.{name} = [{lo:g}, {hi:g}]{unit} is not inside the box the "
                             f"emulator was fitted on [{low:g}, {high:g}]{unit}; refit the emulator on this box, or give "
                             f"inputs.{name} inside it")
        lower.append(max(lo, low))
        upper.append(min(hi, high))
    return np.array(lower), np.array(upper)


def observed_vector(table: pd.DataFrame, shots, feature_names, source: str) -> np.ndarray:
    """The measured features of `shots`, shot-major; a shot without a row or with two (whatever their
    values: which one is meant cannot be told), and missing or non-positive values, are errors."""
    from shockcal.io import require_columns  # pyarrow's import is paid only by the study

    require_columns(table, ["shot", *feature_names], source)
    names = table["shot"].astype(str).str.strip()
    values = []
    for shot in shots:
        rows = table[names == shot]
        if rows.empty:
            raise InputError(f"{source}: no observed features for shot {shot} (have {sorted(names)})")
        if len(rows) > 1:
            raise InputError(f"{source}: shot {shot} has {len(rows)} rows (rows {np.flatnonzero(names == shot).tolist()}); "
                             "give one row per shot")
        row = pd.to_numeric(rows.iloc[0][feature_names], errors="coerce").to_numpy(dtype=float)   # text: NaN
        bad = [f for f, v in zip(feature_names, row) if not np.isfinite(v) or v <= 0]
        if bad:
            raise InputError(f"{source}: shot {shot}: observed feature(s) {bad} missing or not positive")
        values.append(row)
    return np.concatenate(values)


def readout_vector(table: pd.DataFrame, shots, feature_names, source: str) -> np.ndarray:
    """The read-out sds (m/s) of `shots`' features, shot-major, from the table's `readout_sd_<feature>`
    columns (0 for a feature without one: a published or hand-made table); a negative or non-numeric
    value is an error naming the shot and the column."""
    names = table["shot"].astype(str).str.strip()
    values = []
    for shot in shots:
        row = table[names == shot].iloc[0]
        for feature in feature_names:
            column = f"readout_sd_{feature}"
            value = pd.to_numeric(row.get(column, 0.0), errors="coerce")
            if not np.isfinite(value) or value < 0:
                raise InputError(f"{source}: shot {shot}: {column} = {row.get(column)!r} is not a sd (m/s, >= 0)")
            values.append(float(value))
    return np.array(values)


def log_density(log_likelihood, lambda_y):
    """Log posterior density of (theta, lambda_y) up to a constant: the log-likelihood plus lambda_y's
    Gamma prior (theta's prior is uniform on the box)."""
    shape, rate = LAMBDA_Y_PRIOR
    return np.asarray(log_likelihood) + stats.gamma.logpdf(lambda_y, shape, scale=1.0 / rate)
