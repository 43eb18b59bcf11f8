"""Principal-component Gaussian-process emulator of the calibration features (SPEC section 5).

`PCGPEmulator` works on plain arrays (inputs X in a box, outputs Y): outputs are standardized per
column, projected on an orthogonal basis from the SVD of the standardized training outputs, and each
basis weight gets its own GP (`shockcal.gp`) over inputs scaled to [0, 1]. Prediction returns the mean
and covariance of the outputs, adding the covariance of what the truncated basis leaves out, with each
output's sd scaled by a factor calibrated by K-fold. Cross-validation: closed-form LOO (diagnostic),
K-fold and the outer check (everything refitted).

The study's `Emulator` (`fit_emulator` on an `EmulatorSpec`) maps design columns to emulator
inputs, in one of two structures (config `emulator.structure`):
- `per_shot`: one emulator per shot over that shot's own inputs (A, B, C, n, m, V_i, G_i), with
  G_i the sum of its shear-modulus inputs (SPEC section 3); shots are independent.
- `joint`: the paper's single emulator of all shots' features over all inputs.

Saved as `emulator.npz` (arrays) + `emulator.json` (format version, structure, names, units,
settings, hyperparameters); loading rebuilds the Cholesky factors, so files stay small and no live
object is pickled.
"""

from __future__ import annotations

import json
import logging
from collections.abc import Mapping
from concurrent.futures import ThreadPoolExecutor
from dataclasses import asdict, dataclass, field, replace
from functools import cache
from pathlib import Path

import numpy as np
import pandas as pd
from joblib import Parallel, delayed
from scipy.special import expit
from threadpoolctl import ThreadpoolController, threadpool_limits

from shockcal.config import STRENGTH_INPUTS, prior_bounds
from shockcal.design import ShotMapping
from shockcal.error_model import ErrorModel
from shockcal.errors import InputError
from shockcal.gp import GaussianProcess, Hyper
from shockcal.io import atomic_path
from shockcal.seeds import stream_seed

FORMAT_VERSION = 4                  # 4: the error model (3 had no error tails, 2 the strain^n input only)
CALIBRATION_FEATURES = ["v_elastic", "v_plastic", "v_slope1", "v_slope2"]
Z90 = 1.6449                        # half-width of a central 90% normal band, in sd
SWITCH_WIDTH = 0.02                 # width of the logistic step between regimes, in the switch's ratio
SWITCH_MIN_RUNS = 30                # held-out values past a switch needed for its own sd factor
PREDICT_BATCH = 1000                # points per batch of a prediction (memory: components x batch x runs)
# extra emulator inputs base^column: config emulator key of the base, design column
POWER_INPUTS = [("hardening_strain", "n"), ("homologous_temperature", "m")]
log = logging.getLogger("shockcal.emulator")


@dataclass
class InputMap:
    """How one emulator's inputs derive from design inputs: each is a sum of design columns, then
    one input base^column for each entry of `powers`: the Johnson-Cook factors eps^n at a plastic
    strain eps and T*^m at a homologous temperature T*. Both are steep near n = 0 and m = 0, where
    the features change fastest, and smooth and monotone everywhere."""

    names: list[str]            # emulator input names, e.g. [A, B, C, n, m, V2, G_105S]
    terms: list[list[str]]      # design columns summed into each input
    lower: np.ndarray           # box of each input (sum of the terms' bounds), the powers last
    upper: np.ndarray
    powers: list[tuple[float, str]] = field(default_factory=list)   # (base, design column)

    def design_inputs(self) -> list[str]:
        return list(dict.fromkeys(t for terms in self.terms for t in terms))

    def raw(self, inputs) -> np.ndarray:
        """(N, d) inputs (sums of design columns, strain^n) from a mapping or DataFrame of design columns."""
        raw = [sum(np.asarray(inputs[t], dtype=float) for t in terms) for terms in self.terms]
        raw += [base ** np.asarray(inputs[column], dtype=float) for base, column in self.powers]
        return np.column_stack(raw)

    def scaled(self, inputs) -> np.ndarray:
        """(N, d) inputs scaled to [0, 1] by the box."""
        return (self.raw(inputs) - self.lower) / (self.upper - self.lower)

    def to_json(self) -> dict:
        return {"names": self.names, "terms": self.terms, "lower": self.lower.tolist(), "upper": self.upper.tolist(),
                "powers": [list(p) for p in self.powers]}

    @classmethod
    def from_json(cls, d: dict) -> InputMap:
        return cls(d["names"], d["terms"], np.array(d["lower"]), np.array(d["upper"]),
                   [(float(b), str(c)) for b, c in d["powers"]])


def shot_input_map(shot: ShotMapping, bounds: Mapping[str, tuple[float, float]], powers=()) -> InputMap:
    """A per-shot emulator's inputs: A, B, C, n, m, the shot's velocity, its summed shear modulus,
    then the `powers` (base, design column); `bounds`: the prior box by design input."""
    terms = [[k] for k in STRENGTH_INPUTS] + [[shot.velocity_input], list(shot.shear_modulus_inputs)]
    names = [*STRENGTH_INPUTS, shot.velocity_input, f"G_{shot.shot}"]
    return _box_map(bounds, names, terms, powers)


def joint_input_map(shots: list[ShotMapping], bounds: Mapping[str, tuple[float, float]], powers=()) -> InputMap:
    """The joint emulator's inputs: every design input the shots use, each on its own, then the `powers`."""
    used = list(dict.fromkeys(k for shot in shots for k in shot.inputs()))
    return _box_map(bounds, used, [[k] for k in used], powers)


def _box_map(bounds, names, terms, powers) -> InputMap:
    lower = [sum(bounds[t][0] for t in ts) for ts in terms]
    upper = [sum(bounds[t][1] for t in ts) for ts in terms]
    for base, column in powers:             # base < 1: base^column falls as the column grows
        lower.append(base ** bounds[column][1])
        upper.append(base ** bounds[column][0])
    return InputMap(names, terms, np.array(lower), np.array(upper), list(powers))


@dataclass
class Settings:
    """How a PCGPEmulator is fitted (config `emulator`, or keyword arguments from a notebook)."""

    family: str = "matern52"       # correlation family (correlation.FAMILIES)
    fit_mean: bool = True          # per-component constant mean (GLS), else zero
    n_components: float = 0.999    # integer count, or variance fraction in (0, 1)
    n_starts: int = 2              # L-BFGS-B starts per GP
    max_fit_runs: int = 500        # hyperparameters fitted on at most this many runs (seeded subset)
    seed: int = 0
    n_jobs: int = 1                # processes for the GP fits, threads for prediction (one BLAS thread each)
    cv_folds: int = 10             # K-fold of the sd calibration
    calibrate_sd: bool = True      # scale each feature's sd so that K-fold 90% bands hold 90%
    cv_warm_start: bool = True     # refit each fold from the full fit's hyperparameters (one start)
    switch_ratio: float = 0.9      # a Switch's ratio past which its own sd factors apply; 0: off
    error_tails: str = "student_t"  # error model fitted to the K-fold: student_t (dof, scale) or gaussian

    @classmethod
    def from_config(cls, settings: dict, seed: int) -> Settings:
        keys = ("family", "fit_mean", "n_components", "n_starts", "max_fit_runs", "n_jobs", "cv_folds", "calibrate_sd",
                "cv_warm_start", "switch_ratio", "error_tails")
        return cls(seed=seed, **{k: settings[k] for k in keys if k in settings})


@dataclass(frozen=True)
class EmulatorSpec:
    """What the study's emulator is fitted over: its structure (`per_shot` or `joint`), how each shot
    reads the design, the prior box by design input (native units), the extra power inputs (base,
    design column; `InputMap`) and the GP settings, whose seed keys each block's own random stream."""

    structure: str
    shots: Mapping[str, ShotMapping]
    bounds: Mapping[str, tuple[float, float]]
    powers: tuple[tuple[float, str], ...] = ()
    settings: Settings = field(default_factory=Settings)

    @classmethod
    def from_config(cls, config: dict, shots) -> EmulatorSpec:
        """The adapter from a validated config (`emulator`, `inputs`, `shots`, study.seed) for `shots`."""
        section = config["emulator"]
        powers = tuple((section[key], column) for key, column in POWER_INPUTS if section[key])
        return cls(section["structure"], {s: ShotMapping.from_config(config, s) for s in shots}, prior_bounds(config),
                   powers, Settings.from_config(section, config["study"]["seed"]))


@dataclass
class Switch:
    """A regime switch of the outputs: past mean[numerator] / mean[denominator] = switch_ratio
    (columns of Y; e.g. v_elastic / v_plastic near 1, a single-wave trace), the `affected` columns
    get sd factors of their own, since the emulator's error there differs from the bulk's."""

    numerator: int
    denominator: int
    affected: list[int]


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


def _fit_hyper(x, w, fit_rows, settings: Settings, seed: int | np.random.SeedSequence, start: Hyper | None) -> Hyper:
    """MAP hyperparameters of one basis weight's GP, on one BLAS thread."""
    with threadpool_limits(1):
        return GaussianProcess.fit(x, w, n_starts=settings.n_starts, seed=seed, fit_rows=fit_rows,
                                   family=settings.family, fit_mean=settings.fit_mean, start=start).hyper


@cache
def _blas_threads() -> ThreadpoolController:
    """The process's thread pools, inspected once (a fresh inspection costs ~2.5 ms per prediction)."""
    return ThreadpoolController()


class PCGPEmulator:
    """Principal-component GP emulator on plain arrays: inputs X (N, d) in a box, outputs Y (N, F).

    >>> emu = PCGPEmulator.fit(X, Y, lower, upper, Settings(family="matern52"))
    >>> mean, cov = emu.predict(X_new)            # (M, F), (M, F, F)
    >>> cv = emu.cross_validate(10)               # refits everything per fold
    """

    def __init__(self, lower, upper, mean, scale, basis, residual_cov, x_train, y_train, hypers: list[Hyper],
                 settings: Settings, sd_factor=None, switches=None, error: ErrorModel | None = None):
        self.lower, self.upper = np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)
        self.mean, self.scale, self.basis = np.asarray(mean), np.asarray(scale), np.asarray(basis)
        self.residual_cov = np.asarray(residual_cov)
        self.x_train, self.y_train = np.asarray(x_train, dtype=float), np.asarray(y_train, dtype=float)
        self.settings = settings
        # sd factors (2, F): row 0 in the usual regime, row 1 past a switch (see `switch_weight`)
        self.sd_factor = np.ones((2, len(self.mean))) if sd_factor is None else np.asarray(sd_factor, dtype=float)
        self.switches: list[Switch] = list(switches or [])
        self.kfold: HeldOut | None = None          # the K-fold of the sd calibration, kept for reporting
        self.error = error or ErrorModel()         # the error's distribution around (mean, covariance)
        self.weights = self.project((self.y_train - self.mean) / self.scale)
        self.gps = [GaussianProcess(self.x_train, self.weights[:, j], h, family=settings.family)
                    for j, h in enumerate(hypers)]

    def project(self, z: np.ndarray) -> np.ndarray:
        """Basis weights of standardized outputs z (least squares on the orthogonal basis)."""
        return z @ self.basis.T / np.sum(self.basis**2, axis=1)

    def scaled(self, X) -> np.ndarray:
        return (np.asarray(X, dtype=float) - self.lower) / (self.upper - self.lower)

    @classmethod
    def fit(cls, X, Y, lower, upper, settings: Settings | None = None, starts: list[Hyper] | None = None,
            switches: list[Switch] | None = None) -> PCGPEmulator:
        """Standardize Y, build the basis, fit one GP per basis weight at its posterior mode (from
        `starts`, one per component, if given; else from `settings.n_starts` starts).

        With `settings.calibrate_sd`, a K-fold follows and each feature's sd is scaled by the 90%
        quantile of its K-fold |error| / sd over 1.645: one factor per feature, never per run, and
        a second one for the feature's held-out values past a regime `switch` (e.g. single-wave
        traces), when there are at least SWITCH_MIN_RUNS of them.

        With `settings.error_tails == "student_t"`, the error model's (dof, scale) are fitted to
        the Mahalanobis distances of the same K-fold's errors (`shockcal.error_model`).
        """
        settings = settings or Settings()
        model = cls._fit_many(X, Y, lower, upper, settings, [np.arange(len(Y))], starts)[0]
        model.switches = list(switches or [])
        if settings.calibrate_sd or settings.error_tails == "student_t":
            held, folds = model._kfold(settings.cv_folds, settings.seed)
            if settings.calibrate_sd:
                model.sd_factor = _sd_factor(model, held, np.ones(len(held.rows), dtype=bool))
                held = _cross_fitted(model, held, folds)
            model.kfold = held
            if settings.error_tails == "student_t":
                model.error = ErrorModel.fit(*held.distances(model.y_train))
                log.info("error model: Student t, dof %.2f, scale %.3f (from %d K-fold errors)",
                         model.error.dof, model.error.scale, len(held.rows))
        return model

    @classmethod
    def _fit_many(cls, X, Y, lower, upper, settings: Settings, row_sets, starts=None) -> list[PCGPEmulator]:
        """One emulator per set of training rows, all GP fits in one (parallel) batch. `starts`:
        hyperparameters to start component j's fit from (a refit of the same data's subsets)."""
        X, Y = np.asarray(X, dtype=float), np.asarray(Y, dtype=float)
        x_all = (X - np.asarray(lower, dtype=float)) / (np.asarray(upper, dtype=float) - np.asarray(lower, dtype=float))
        parts, tasks = [], []
        for rows in row_sets:
            x, y = x_all[rows], Y[rows]
            mean, scale = y.mean(0), y.std(0)
            scale = np.where(scale > 0, scale, 1.0)
            z = (y - mean) / scale
            u, s, vt = np.linalg.svd(z, full_matrices=False)
            p = _component_count(s, settings.n_components)
            n = len(y)
            weights = u[:, :p] * np.sqrt(n)                   # unit-variance weights
            basis = vt[:p] * (s[:p, None] / np.sqrt(n))       # z ~ weights @ basis
            residual = z - weights @ basis
            # children of the seed: the fit subset, then one per component's GP starts (the root draws the folds)
            subset_seed, *component_seeds = np.random.SeedSequence(settings.seed).spawn(1 + p)
            fit_rows = (None if n <= settings.max_fit_runs else
                        np.sort(np.random.default_rng(subset_seed).choice(n, settings.max_fit_runs, replace=False)))
            parts.append((x, y, mean, scale, basis, residual.T @ residual / n))
            tasks += [(x, weights[:, j], fit_rows, settings, component_seeds[j],
                       starts[j] if starts is not None and j < len(starts) else None) for j in range(p)]
        if settings.n_jobs > 1:
            hypers = Parallel(n_jobs=settings.n_jobs)(delayed(_fit_hyper)(*t) for t in tasks)
        else:
            hypers = [_fit_hyper(*t) for t in tasks]
        out, start = [], 0
        for x, y, mean, scale, basis, residual_cov in parts:
            p = len(basis)
            out.append(cls(lower, upper, mean, scale, basis, residual_cov, x, y, hypers[start:start + p],
                           settings))
            start += p
        return out

    def predict(self, X) -> tuple[np.ndarray, np.ndarray]:
        """Mean (N, F) and covariance (N, F, F) at inputs X (N, d) in the box's units."""
        return self.predict_scaled(self.scaled(X))

    def predict_scaled(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Mean (N, F) and covariance (N, F, F) at inputs x scaled to [0, 1]."""
        w_mean, w_var = self._predict_weights(np.ascontiguousarray(x, dtype=float))
        z_cov = np.einsum("nj,jf,jg->nfg", w_var, self.basis, self.basis) + self.residual_cov
        mean = self.mean + (w_mean @ self.basis) * self.scale
        sd_scale = self.scale * self.sd_factors(mean)                              # (N, F)
        return mean, z_cov * sd_scale[:, :, None] * sd_scale[:, None, :]

    def error_groups(self) -> list[tuple[np.ndarray, ErrorModel]]:
        """All outputs in one group with this emulator's error model (a calibration `Problem`'s
        `error_groups` from a notebook)."""
        return [(np.arange(len(self.mean)), self.error)]

    def switch_weight(self, mean: np.ndarray) -> np.ndarray:
        """(N, F) weight of the switched regime at predicted means: for each switch's columns a
        logistic step in mean[numerator] / mean[denominator] at `settings.switch_ratio` (width
        SWITCH_WIDTH), smooth so that the calibration likelihood stays smooth; 0 elsewhere."""
        weight = np.zeros_like(mean)
        if self.settings.switch_ratio:
            for sw in self.switches:
                with np.errstate(divide="ignore", invalid="ignore"):
                    ratio = mean[:, sw.numerator] / mean[:, sw.denominator]
                step = expit((np.nan_to_num(ratio, nan=0.0) - self.settings.switch_ratio) / SWITCH_WIDTH)
                weight[:, sw.affected] = step[:, None]
        return weight

    def sd_factors(self, mean: np.ndarray) -> np.ndarray:
        """(N, F) sd factors at predicted means, blending the usual and the switched regime's."""
        return _blend(self.sd_factor, self.switch_weight(mean))

    def _predict_weights(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Mean and variance (N, p) of each basis weight at scaled inputs x, on `settings.n_jobs`
        threads: the components' cross-covariances on Python threads (numba's kernel releases the
        GIL), then their triangular solves on BLAS threads (scipy's LAPACK wrappers hold the GIL).
        In batches of PREDICT_BATCH points, which bounds the memory of the cross-covariances."""
        threads = self.settings.n_jobs
        means, variances = [], []
        for start in range(0, len(x), PREDICT_BATCH):
            batch = x[start:start + PREDICT_BATCH]
            with ThreadPoolExecutor(threads) as pool:
                cross = list(pool.map(lambda gp: gp.prior_cov(batch, gp.x), self.gps))  # noqa: B023 (used at once)
            with _blas_threads().limit(limits=threads, user_api="blas"):
                parts = [gp.predict_from_cross_cov(k) for gp, k in zip(self.gps, cross)]
            means.append(np.column_stack([m for m, _ in parts]))
            variances.append(np.column_stack([v for _, v in parts]))
        return np.concatenate(means), np.concatenate(variances)

    def loo(self) -> HeldOut:
        """Closed-form leave-one-out (hyperparameters and basis fixed): a fast diagnostic that flatters."""
        w_mean = np.empty_like(self.weights)
        w_var = np.empty_like(self.weights)
        for j, gp in enumerate(self.gps):
            w_mean[:, j], w_var[:, j] = gp.loo()
        z_var = w_var @ self.basis**2 + np.diag(self.residual_cov)
        mean = self.mean + (w_mean @ self.basis) * self.scale
        return HeldOut("loo_closed_form", np.arange(len(self.y_train)),
                       mean, np.sqrt(z_var) * self.scale * self.sd_factors(mean))

    def cross_validate(self, k: int = 10, seed: int | None = None) -> HeldOut:
        """K-fold (seeded folds): standardization, basis and hyperparameters refitted on each fold.

        With `calibrate_sd`, each fold's sd is scaled by factors estimated from the other folds.
        """
        seed = self.settings.seed if seed is None else seed
        if self.kfold is not None and (k, seed) == (self.settings.cv_folds, self.settings.seed):
            return self.kfold
        held, folds = self._kfold(k, seed)
        return _cross_fitted(self, held, folds) if self.settings.calibrate_sd else held

    def _kfold(self, k: int, seed: int) -> tuple[HeldOut, list[np.ndarray]]:
        """K-fold held-out predictions with the fold models' own sd, and the folds."""
        n = len(self.y_train)
        order = np.random.default_rng(seed).permutation(n)
        folds = [np.sort(f) for f in np.array_split(order, min(k, n))]
        trains = [np.setdiff1d(np.arange(n), f) for f in folds]
        return self._held_out("kfold", folds, trains), folds

    def outer_check(self, margin: float = 0.05, columns=None) -> HeldOut:
        """Train on runs with every scaled input (of `columns`, default all) in [margin, 1 - margin];
        predict the others (near the faces)."""
        x = self.x_train if columns is None else self.x_train[:, columns]
        inner = np.all((x >= margin) & (x <= 1 - margin), axis=1)
        if inner.sum() < self.x_train.shape[1] + 2:
            log.warning("outer check skipped: %d runs inside the inner box, %d needed", inner.sum(),
                        self.x_train.shape[1] + 2)
            empty = np.empty((0, self.y_train.shape[1]))
            return HeldOut("outer", np.empty(0, dtype=int), empty, empty)
        held = self._held_out("outer", [np.flatnonzero(~inner)], [np.flatnonzero(inner)])
        return held.scaled(self.sd_factors(held.mean))

    def _held_out(self, scheme, tests, trains) -> HeldOut:
        starts = [gp.hyper for gp in self.gps] if self.settings.cv_warm_start else None
        models = self._fit_many(self.x_train, self.y_train, np.zeros(len(self.lower)), np.ones(len(self.upper)),
                                self.settings, trains, starts)
        rows = np.concatenate(tests)
        f = self.y_train.shape[1]
        mean, cov = np.empty((len(rows), f)), np.empty((len(rows), f, f))
        start = 0
        for model, test in zip(models, tests):
            mean[start:start + len(test)], cov[start:start + len(test)] = model.predict_scaled(self.x_train[test])
            start += len(test)
        return HeldOut(scheme, rows, mean, np.sqrt(np.einsum("nff->nf", cov)), cov)

    def to_arrays(self, prefix: str = "") -> dict:
        arrays = {"lower": self.lower, "upper": self.upper, "mean": self.mean, "scale": self.scale,
                  "basis": self.basis, "residual_cov": self.residual_cov, "x_train": self.x_train,
                  "y_train": self.y_train, "sd_factor": self.sd_factor}
        return {f"{prefix}{k}": v for k, v in arrays.items()}

    def to_json(self) -> dict:
        return {"settings": asdict(self.settings), "switches": [asdict(sw) for sw in self.switches],
                "error": self.error.to_json(),
                "hyperparameters": [{"lambda_w": g.hyper.lambda_w, "beta": g.hyper.beta.tolist(),
                                     "lambda_n": g.hyper.lambda_n, "mean": g.hyper.mean} for g in self.gps]}

    @classmethod
    def from_saved(cls, meta: dict, arrays, prefix: str = "") -> PCGPEmulator:
        hypers = [Hyper(h["lambda_w"], np.array(h["beta"]), h["lambda_n"], h["mean"]) for h in meta["hyperparameters"]]
        fields = ("lower", "upper", "mean", "scale", "basis", "residual_cov", "x_train", "y_train")
        return cls(*(arrays[f"{prefix}{k}"] for k in fields), hypers, Settings(**meta["settings"]),
                   arrays[f"{prefix}sd_factor"], [Switch(**sw) for sw in meta["switches"]],
                   ErrorModel.from_json(meta["error"]))

    def save(self, path) -> Path:
        """One .npz file: the arrays plus a JSON header (format, version, settings, hyperparameters)."""
        path = Path(path)
        header = {"format": "shockcal-pcgp", "version": FORMAT_VERSION, **self.to_json()}
        with atomic_path(path) as tmp:
            np.savez(tmp, header=np.array(json.dumps(header)), **self.to_arrays())
        return path

    @classmethod
    def load(cls, path) -> PCGPEmulator:
        with np.load(path) as npz:
            arrays = dict(npz)
        header = json.loads(str(arrays.pop("header")))
        if header.get("format") != "shockcal-pcgp" or header.get("version") != FORMAT_VERSION:
            raise InputError(f"{path}: not a shockcal PC-GP emulator of version {FORMAT_VERSION}")
        return cls.from_saved(header, arrays)


def _sd_factor(model: PCGPEmulator, held: HeldOut, use: np.ndarray) -> np.ndarray:
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


def _blend(factors: np.ndarray, weight: np.ndarray) -> np.ndarray:
    """(N, F) factors: the usual regime's, moved towards the switched one's by weight (N, F)."""
    return factors[0] + weight * (factors[1] - factors[0])


def _cross_fitted(model: PCGPEmulator, held: HeldOut, folds) -> HeldOut:
    """K-fold sd scaled, fold by fold, by the factors of the other folds (an honest coverage)."""
    fold_of = np.concatenate([np.full(len(f), j) for j, f in enumerate(folds)])
    factors = np.empty_like(held.sd)
    for j in range(len(folds)):
        here = fold_of == j
        factors[here] = _blend(_sd_factor(model, held, ~here), model.switch_weight(held.mean[here]))
    return held.scaled(factors)


def _component_count(singular_values: np.ndarray, n_components: float) -> int:
    """An integer count, or the fewest components explaining a variance fraction in (0, 1)."""
    if n_components >= 1:
        return int(min(n_components, len(singular_values)))
    explained = np.cumsum(singular_values**2) / np.sum(singular_values**2)
    return int(np.searchsorted(explained, n_components) + 1)


@dataclass
class Block:
    """One PC-GP emulator of some shots' features over design inputs combined by an input map."""

    input_map: InputMap
    shots: list[str]
    runs: np.ndarray
    model: PCGPEmulator


class Emulator:
    """The study's emulator: one block per shot (per_shot) or one for all shots (joint)."""

    feature_names = CALIBRATION_FEATURES

    def __init__(self, structure: str, blocks: list[Block], bounds: dict, shot_inputs: dict):
        self.structure = structure
        self.blocks = blocks
        self.shots = [s for b in blocks for s in b.shots]
        self._bounds = bounds            # design input -> (min, max), native units
        self._shot_inputs = shot_inputs  # shot -> design inputs it depends on (SPEC section 3)

    def required_inputs(self, shots) -> list[str]:
        """Design inputs a calibration of `shots` needs, in the box's order."""
        self._check_shots(shots)
        needed = {t for shot in shots for t in self._shot_inputs[shot]}
        return [k for k in self._bounds if k in needed]

    def input_bounds(self, names) -> tuple[np.ndarray, np.ndarray]:
        return (np.array([self._bounds[k][0] for k in names]), np.array([self._bounds[k][1] for k in names]))

    def predict(self, inputs, shots) -> tuple[np.ndarray, np.ndarray]:
        """Mean (N, 4 len(shots)) m/s and covariance (N, F, F) (m/s)^2 at design inputs (native units).

        `inputs` maps design column names to arrays of N values. A joint emulator also depends on
        inputs of shots not asked for; those are held at mid-box (they only enter its GPs).
        """
        shots = list(shots)
        self._check_shots(shots)
        n = len(np.atleast_1d(np.asarray(inputs[self.required_inputs(shots)[0]])))
        k = len(self.feature_names)
        mean = np.empty((n, k * len(shots)))
        cov = np.zeros((n, k * len(shots), k * len(shots)))
        for block in self.blocks:
            wanted = [s for s in shots if s in block.shots]
            if not wanted:
                continue
            m, c = block.model.predict(block.input_map.raw(self._complete(inputs, block, n)))
            src = np.concatenate([np.arange(k) + k * block.shots.index(s) for s in wanted])
            dst = np.concatenate([np.arange(k) + k * shots.index(s) for s in wanted])
            mean[:, dst] = m[:, src]
            cov[:, dst[:, None], dst[None, :]] = c[:, src[:, None], src[None, :]]
        return mean, cov

    def error_groups(self, shots) -> list[tuple[np.ndarray, ErrorModel]]:
        """Per block, the columns of `predict(..., shots)` it predicts and its error model: blocks'
        errors are independent, so a likelihood is the sum of one error density per group."""
        shots = list(shots)
        self._check_shots(shots)
        k = len(self.feature_names)
        return [(np.concatenate([np.arange(k) + k * shots.index(s) for s in block.shots if s in shots]),
                 block.model.error) for block in self.blocks if set(block.shots) & set(shots)]

    def _complete(self, inputs, block: Block, n: int) -> dict:
        """The block's design inputs, those not given held at mid-box."""
        return {t: np.asarray(inputs[t], dtype=float) if t in inputs else np.full(n, np.mean(self._bounds[t]))
                for t in block.input_map.design_inputs()}

    def _check_shots(self, shots):
        missing = [s for s in shots if s not in self.shots]
        if missing:
            raise InputError(f"the emulator has no shot {missing}; it was fitted for {self.shots}")

    def cv_table(self, scheme: str = "loo_closed_form", folds: int = 10, margin: float = 0.05) -> pd.DataFrame:
        """Held-out table (run, shot, feature, simulated, predicted, predicted_sd in m/s, scheme).

        Schemes: `loo_closed_form` (fast diagnostic, hyperparameters fixed), `kfold` (everything
        refitted per fold) and `outer` (trained on runs whose design inputs are all in the inner box
        [margin, 1 - margin], predicting the rest).
        """
        k = len(self.feature_names)
        parts = []
        for block in self.blocks:
            if scheme == "loo_closed_form":
                held = block.model.loo()
            elif scheme == "kfold":
                held = block.model.cross_validate(folds)
            else:
                held = block.model.outer_check(margin, np.arange(len(block.input_map.terms)))
            for i, shot in enumerate(block.shots):
                for f, feature in enumerate(self.feature_names):
                    col = k * i + f
                    parts.append(pd.DataFrame({"run": block.runs[held.rows], "shot": shot, "feature": feature,
                                               "simulated": block.model.y_train[held.rows, col],
                                               "predicted": held.mean[:, col], "predicted_sd": held.sd[:, col],
                                               "scheme": scheme}))
        return pd.concat(parts, ignore_index=True)

    def save(self, directory) -> Path:
        """Write emulator.npz (arrays) and emulator.json (version, names, settings, hyperparameters)."""
        directory = Path(directory)
        directory.mkdir(parents=True, exist_ok=True)
        arrays = {}
        for i, block in enumerate(self.blocks):
            arrays.update(block.model.to_arrays(f"block{i}/"))
            arrays[f"block{i}/runs"] = block.runs
        with atomic_path(directory / "emulator.npz") as tmp:
            np.savez(tmp, **arrays)
        meta = {"format": "shockcal-emulator", "version": FORMAT_VERSION, "structure": self.structure,
                "feature_names": self.feature_names, "feature_units": "m/s",
                "input_bounds": {k: list(v) for k, v in self._bounds.items()}, "shot_inputs": self._shot_inputs,
                "blocks": [{"shots": b.shots, "inputs": b.input_map.to_json(), **b.model.to_json()}
                           for b in self.blocks]}
        with atomic_path(directory / "emulator.json") as tmp:     # written last: it marks a finished save
            tmp.write_text(json.dumps(meta, indent=1))
        return directory

    @classmethod
    def load(cls, directory) -> Emulator:
        """Read a saved emulator, refusing other formats and versions with a clear message."""
        directory = Path(directory)
        meta_path = directory / "emulator.json"
        if not meta_path.is_file() or not (directory / "emulator.npz").is_file():
            raise InputError(f"{directory}: not an emulator directory (emulator.json + emulator.npz expected)")
        meta = json.loads(meta_path.read_text())
        if meta.get("format") != "shockcal-emulator" or meta.get("version") != FORMAT_VERSION:
            raise InputError(f"{meta_path}: emulator format {meta.get('format')!r} version {meta.get('version')}; "
                             f"this shockcal reads version {FORMAT_VERSION}: refit it with `shockcal emulate`")
        with np.load(directory / "emulator.npz") as npz:
            arrays = dict(npz)
        blocks = [Block(InputMap.from_json(b["inputs"]), b["shots"], arrays[f"block{i}/runs"],
                        PCGPEmulator.from_saved(b, arrays, f"block{i}/")) for i, b in enumerate(meta["blocks"])]
        return cls(meta["structure"], blocks, {k: tuple(v) for k, v in meta["input_bounds"].items()},
                   meta["shot_inputs"])


def training_data(design: pd.DataFrame, features: pd.DataFrame, shot: str, source: str) -> pd.DataFrame:
    """Join one shot's features to the design on `run`; drop failed or NaN runs with a logged count."""
    from shockcal.io import require_columns

    require_columns(features, ["run", *CALIBRATION_FEATURES], source)
    unknown = sorted(set(features["run"]) - set(design["run"]))
    if unknown:
        raise InputError(f"{source}: runs {unknown[:5]} of shot {shot} are not in the design")
    usable = features[CALIBRATION_FEATURES].notna().all(axis=1)
    if "status" in features.columns:
        usable &= features["status"].eq("ok")
    dropped = int((~usable).sum())
    if dropped:
        log.info("shot %s: %d of %d runs dropped (failed or NaN features)", shot, dropped, len(features))
    return design.merge(features.loc[usable, ["run", *CALIBRATION_FEATURES]], on="run", how="inner")


def _check_training_inputs(table: pd.DataFrame, input_map: InputMap, label: str) -> None:
    """Enough runs, no constant input, everything inside the prior box."""
    design_cols = input_map.design_inputs()
    if len(table) < len(input_map.names) + 2:
        raise InputError(f"{label}: {len(table)} usable runs; at least {len(input_map.names) + 2} "
                         f"(inputs + 2) are needed to fit an emulator")
    for col in design_cols:
        if table[col].nunique() < 2:
            raise InputError(f"{label}: input {col} is constant over the training runs")
    x = input_map.scaled(table)
    outside = (x < -1e-9) | (x > 1 + 1e-9)
    if outside.any():
        row, col = np.argwhere(outside)[0]
        raise InputError(f"{label}: run {table['run'].iloc[row]}: input {input_map.names[col]} lies outside "
                         f"the prior box [{input_map.lower[col]}, {input_map.upper[col]}]")


def fit_emulator(design: pd.DataFrame, features: dict[str, pd.DataFrame], spec: EmulatorSpec,
                 sources: dict[str, str] | None = None) -> Emulator:
    """Fit the study's emulator to a design (Table IV units) and per-shot feature tables (m/s, us),
    joined on `run`; block i fits with stream ("emulator", i) of `spec.settings.seed`."""
    shots = list(features)
    unmapped = [shot for shot in shots if shot not in spec.shots]
    if unmapped:
        raise InputError(f"features of shots {unmapped}: the emulator spec maps only {list(spec.shots)}")
    mappings = [spec.shots[shot] for shot in shots]
    sources = sources or {shot: f"features of {shot}" for shot in shots}
    tables = {shot: training_data(design, features[shot], shot, sources[shot]) for shot in shots}
    if spec.structure == "per_shot":
        groups = [([m.shot], shot_input_map(m, spec.bounds, spec.powers), tables[m.shot], sources[m.shot],
                   CALIBRATION_FEATURES) for m in mappings]
    else:
        joined = tables[shots[0]].rename(columns={f: f"{shots[0]}:{f}" for f in CALIBRATION_FEATURES})
        for shot in shots[1:]:
            joined = joined.merge(tables[shot][["run", *CALIBRATION_FEATURES]].rename(
                columns={f: f"{shot}:{f}" for f in CALIBRATION_FEATURES}), on="run", how="inner")
        groups = [(shots, joint_input_map(mappings, spec.bounds, spec.powers), joined, "joint training set",
                   [f"{s}:{f}" for s in shots for f in CALIBRATION_FEATURES])]
    blocks = []
    for i, (block_shots, input_map, table, label, columns) in enumerate(groups):
        _check_training_inputs(table, input_map, label)
        settings = replace(spec.settings, seed=stream_seed(spec.settings.seed, "emulator", i))
        model = PCGPEmulator.fit(input_map.raw(table), table[columns].to_numpy(), input_map.lower, input_map.upper,
                                 settings, switches=single_wave_switches(len(block_shots)))
        log.info("emulator %s: %d runs, %d inputs, %d of %d components, %s correlation", "+".join(block_shots),
                 len(table), len(input_map.names), len(model.gps), len(columns), settings.family)
        blocks.append(Block(input_map, block_shots, table["run"].to_numpy(), model))
    return Emulator(spec.structure, blocks, dict(spec.bounds), {m.shot: m.inputs() for m in mappings})


def single_wave_switches(n_shots: int) -> list[Switch]:
    """Per shot (features in CALIBRATION_FEATURES order, shot after shot): v_elastic / v_plastic
    near 1 marks a single-wave trace, where v_elastic and v_slope1 change meaning."""
    k = len(CALIBRATION_FEATURES)
    elastic, plastic = CALIBRATION_FEATURES.index("v_elastic"), CALIBRATION_FEATURES.index("v_plastic")
    return [Switch(k * i + elastic, k * i + plastic, list(range(k * i, k * (i + 1)))) for i in range(n_shots)]


def rmse_table(cv: pd.DataFrame) -> pd.DataFrame:
    """Per scheme, shot and feature: RMSE, bias (m/s) and 90%-band coverage, plus an overall row per scheme."""
    err = cv["predicted"] - cv["simulated"]
    inside = (err.abs() <= Z90 * cv["predicted_sd"])
    frame = cv.assign(sq=err**2, err=err, inside=inside)
    aggregates = dict(rmse_m_s=("sq", "mean"), bias_m_s=("err", "mean"), coverage90=("inside", "mean"))
    per = frame.groupby(["scheme", "shot", "feature"], sort=False).agg(**aggregates).reset_index()
    overall = frame.groupby("scheme", sort=False).agg(**aggregates).reset_index().assign(shot="all", feature="all")
    table = pd.concat([per, overall], ignore_index=True)
    table["rmse_m_s"] = np.sqrt(table["rmse_m_s"])
    order = {s: i for i, s in enumerate(dict.fromkeys(cv["scheme"]))}
    table = table.sort_values("scheme", key=lambda c: c.map(order), kind="stable")
    return table[["scheme", "shot", "feature", "rmse_m_s", "bias_m_s", "coverage90"]].round(3).reset_index(drop=True)
