"""Principal-component Gaussian-process emulator on plain arrays (SPEC section 5).

`PCGPEmulator` takes inputs X (N, d) in a box and outputs Y (N, F): outputs are standardized per
column, projected on an orthogonal basis from the SVD of the standardized training outputs, and each
basis weight gets its own GP (`shockcal.emulator.gp`) over inputs scaled to [0, 1]. Prediction returns the mean
and covariance of the outputs, adding the covariance of what the truncated basis leaves out, with each
output's sd scaled by a factor calibrated by K-fold (constant per output, or varying smoothly over the
box: `shockcal.emulator.variance_model`), and an error model (`shockcal.emulator.error_model`) around them.
Cross-validation: closed-form LOO (diagnostic), K-fold and the outer check (everything refitted); the
held-out predictions and the sd calibration read from them are `shockcal.emulator.held_out`.
Saved as one .npz (arrays and a JSON header); no live object is pickled.

This module knows nothing of shots or designs: the study's emulator (`shockcal.emulator.study_emulator`) maps design
columns to its inputs.
"""

from __future__ import annotations

import json
import logging
from concurrent.futures import ThreadPoolExecutor
from dataclasses import asdict, dataclass
from functools import cache
from pathlib import Path

import numpy as np
from joblib import Parallel, delayed
from scipy.special import expit
from threadpoolctl import ThreadpoolController, threadpool_limits

from shockcal.emulator.error_model import ErrorModel
from shockcal.emulator.gp import GaussianProcess, Hyper
from shockcal.emulator.held_out import HeldOut, blend_factors, cross_fitted, sd_calibration
from shockcal.emulator.settings import EmulatorSettings
from shockcal.emulator.variance_model import VarianceModel
from shockcal.errors import InputError
from shockcal.io import atomic_path

FORMAT_VERSION = 5                  # 5: the smooth sd model (4 had constant sd factors only, 3 no error tails)
SWITCH_WIDTH = 0.02                 # width of the logistic step between regimes, in the switch's ratio
PREDICT_BATCH = 1000                # points per batch of a prediction (memory: components x batch x runs)
log = logging.getLogger("shockcal.emulator.pcgp")


@dataclass
class Switch:
    """A regime switch of the outputs: past mean[numerator] / mean[denominator] = switch_ratio
    (columns of Y; e.g. v_elastic / v_plastic near 1, a single-wave trace), the `affected` columns
    get sd factors of their own, since the emulator's error there differs from the bulk's."""

    numerator: int
    denominator: int
    affected: list[int]


def _fit_hyper(x, w, fit_rows, settings: EmulatorSettings, seed: int | np.random.SeedSequence,
               start: Hyper | None) -> Hyper:
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

    >>> emu = PCGPEmulator.fit(X, Y, lower, upper, EmulatorSettings(family="matern52"), input_names=["a", "b"])
    >>> mean, cov = emu.predict(X_new)            # (M, F), (M, F, F)
    >>> cv = emu.cross_validate(10)               # refits everything per fold

    `input_names` names the inputs for a `Problem` (`Problem.from_emulator`); default x0, x1, ...
    """


    def __init__(self, lower, upper, mean, scale, basis, residual_cov, x_train, y_train, hypers: list[Hyper],
                 settings: EmulatorSettings, sd_factor=None, switches=None, error: ErrorModel | None = None,
                 variance: VarianceModel | None = None, sd_groups=None):
        self.lower, self.upper = np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)
        self.mean, self.scale, self.basis = np.asarray(mean), np.asarray(scale), np.asarray(basis)
        self.residual_cov = np.asarray(residual_cov)
        self.x_train, self.y_train = np.asarray(x_train, dtype=float), np.asarray(y_train, dtype=float)
        self.settings = settings
        # sd factors (2, F): row 0 in the usual regime, row 1 past a switch (see `switch_weight`)
        self.sd_factor = np.ones((2, len(self.mean))) if sd_factor is None else np.asarray(sd_factor, dtype=float)
        self.switches: list[Switch] = list(switches or [])
        # with sd_model "smooth": the sd varies over the box by exp(g(x) / 2), g shared by each group's outputs
        self.variance = variance
        self.sd_groups: list[list[int]] = [list(g) for g in sd_groups] if sd_groups else [list(range(len(self.mean)))]
        self.kfold: HeldOut | None = None          # the K-fold of the sd calibration, kept for reporting
        self.error = error or ErrorModel()         # the error's distribution around (mean, covariance)
        self._input_names: list[str] | None = None
        self.weights = self.project((self.y_train - self.mean) / self.scale)
        self.gps = [GaussianProcess(self.x_train, self.weights[:, j], h, family=settings.family)
                    for j, h in enumerate(hypers)]

    def project(self, z: np.ndarray) -> np.ndarray:
        """Basis weights of standardized outputs z (least squares on the orthogonal basis)."""
        return z @ self.basis.T / np.sum(self.basis**2, axis=1)

    def scaled(self, X) -> np.ndarray:
        return (np.asarray(X, dtype=float) - self.lower) / (self.upper - self.lower)

    @property
    def input_names(self) -> list[str]:
        return self._input_names or [f"x{i}" for i in range(len(self.lower))]

    def __repr__(self) -> str:
        kfold = ""
        if self.kfold is not None:
            rmse = np.sqrt(np.mean((self.y_train[self.kfold.rows] - self.kfold.mean) ** 2))
            kfold = f", K-fold RMSE {rmse:.3g} (output units)"
        return (f"PCGPEmulator({len(self.x_train)} runs, {len(self.lower)} inputs {self.input_names}, "
                f"{self.y_train.shape[1]} outputs, {len(self.gps)} components, {self.settings.family}{kfold}, "
                f"error {self.error})")

    @classmethod
    def fit(cls, X, Y, lower, upper, settings: EmulatorSettings | None = None, starts: list[Hyper] | None = None,
            switches: list[Switch] | None = None, input_names: list[str] | None = None,
            sd_groups: list[list[int]] | None = None) -> PCGPEmulator:
        """Standardize Y, build the basis, fit one GP per basis weight at its posterior mode (from
        `starts`, one per component, if given; else from `settings.n_starts` starts).

        Args:
            X: training inputs (N, d), inside the box.
            Y: training outputs (N, F), e.g. features in m/s.
            lower, upper: the input box (d,), the inputs' prior box in a calibration.
            settings: how the GPs are fitted (`EmulatorSettings`; default its defaults).
            starts: hyperparameter starts, one per component (e.g. a previous fit's).
            switches: output regime switches that get sd factors of their own (`Switch`).
            input_names: the d inputs' names (default x0, x1, ...).
            sd_groups: with `settings.sd_model == "smooth"`, groups of output columns that share one
                variance model g (default: all outputs in one group).

        With `settings.calibrate_sd`, a K-fold follows and each feature's sd is scaled by the 90%
        quantile of its K-fold |error| / sd over 1.645: one factor per feature, never per run, and
        a second one for the feature's held-out values past a regime `switch` (e.g. single-wave
        traces), when there are at least `held_out.SWITCH_MIN_RUNS` of them. With `settings.sd_model ==
        "smooth"`, the K-fold's log z^2 is first fitted by a smooth variance model g over the box
        (`shockcal.emulator.variance_model`), the sd is multiplied by exp(g(x) / 2), and the constant factors
        are then fitted to the z values so rescaled: g gives the shape over the box, the factors the
        level (and the switched regime's level).

        With `settings.error_tails == "student_t"`, the error model's (dof, scale) are fitted to
        the Mahalanobis distances of the same K-fold's errors (`shockcal.emulator.error_model`).
        """
        settings = settings or EmulatorSettings()
        model = cls._fit_many(X, Y, lower, upper, settings, [np.arange(len(Y))], starts)[0]
        model.switches = list(switches or [])
        model._input_names = list(input_names) if input_names is not None else None
        if sd_groups is not None:
            model.sd_groups = [list(g) for g in sd_groups]
        if settings.calibrate_sd or settings.error_tails == "student_t":
            held, folds = model._kfold(settings.cv_folds, settings.seed)
            if settings.calibrate_sd:
                model.sd_factor, model.variance = sd_calibration(model, held, np.ones(len(held.rows), dtype=bool))
                held = cross_fitted(model, held, folds)
            model.kfold = held
            if settings.error_tails == "student_t":
                model.error = ErrorModel.fit(*held.distances(model.y_train))
                log.info("error model: Student t, dof %.2f, scale %.3f (from %d K-fold errors)",
                         model.error.dof, model.error.scale, len(held.rows))
        return model

    @classmethod
    def _fit_many(cls, X, Y, lower, upper, settings: EmulatorSettings, row_sets, starts=None) -> list[PCGPEmulator]:
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
        raw_sd = np.sqrt(np.einsum("nff->nf", z_cov)) * self.scale
        sd_scale = self.scale * self.sd_factors(mean, x, raw_sd)                   # (N, F)
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

    def sd_factors(self, mean: np.ndarray, x: np.ndarray, raw_sd: np.ndarray) -> np.ndarray:
        """(N, F) sd factors: the constant factors at the predicted means (N, F), blending the usual
        and the switched regime's, times the smooth model's exp(g / 2) at scaled inputs x (N, d) and
        the uncalibrated sd raw_sd (N, F, output units) when there is one."""
        factors = blend_factors(self.sd_factor, self.switch_weight(mean))
        return factors if self.variance is None else factors * self.variance.sd_factors(x, raw_sd)

    def _predict_weights(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Mean and variance (N, p) of each basis weight at scaled inputs x: each component's
        cross-covariance and triangular solve on one of `settings.n_jobs` Python threads, BLAS on
        one thread. numba's kernel releases the GIL and scipy's solve holds it, so the solves run one
        at a time while other components' cross-covariances are computed. A 1000-run solve of 100
        points took 2.2 times the CPU on two BLAS threads as on one (docs/emulator.md, "Speed").
        In batches of PREDICT_BATCH points, which bounds the memory of the cross-covariances."""
        means, variances = [], []
        with ThreadPoolExecutor(self.settings.n_jobs) as pool, _blas_threads().limit(limits=1, user_api="blas"):
            for start in range(0, len(x), PREDICT_BATCH):
                batch = x[start:start + PREDICT_BATCH]
                parts = list(pool.map(lambda gp: gp.predict(batch), self.gps))  # noqa: B023 (used at once)
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
        raw_sd = np.sqrt(z_var) * self.scale
        return HeldOut("loo_closed_form", np.arange(len(self.y_train)),
                       mean, raw_sd * self.sd_factors(mean, self.x_train, raw_sd))

    def cross_validate(self, k: int = 10, seed: int | None = None) -> HeldOut:
        """K-fold (seeded folds): standardization, basis and hyperparameters refitted on each fold.

        With `calibrate_sd`, each fold's sd is scaled by factors estimated from the other folds.
        """
        seed = self.settings.seed if seed is None else seed
        if self.kfold is not None and (k, seed) == (self.settings.cv_folds, self.settings.seed):
            return self.kfold
        held, folds = self._kfold(k, seed)
        return cross_fitted(self, held, folds) if self.settings.calibrate_sd else held

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
        return held.scaled(self.sd_factors(held.mean, self.x_train[held.rows], held.sd))

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
                  "y_train": self.y_train, "sd_factor": self.sd_factor,
                  **(self.variance.to_arrays() if self.variance is not None else {})}
        return {f"{prefix}{k}": v for k, v in arrays.items()}

    def to_json(self) -> dict:
        return {"settings": self.settings.model_dump(), "switches": [asdict(sw) for sw in self.switches],
                "error": self.error.to_json(), "sd_groups": self.sd_groups,
                "variance": None if self.variance is None else self.variance.to_json(),
                "hyperparameters": [{"lambda_w": g.hyper.lambda_w, "beta": g.hyper.beta.tolist(),
                                     "lambda_n": g.hyper.lambda_n, "mean": g.hyper.mean} for g in self.gps]}

    @classmethod
    def from_saved(cls, meta: dict, arrays, prefix: str = "") -> PCGPEmulator:
        hypers = [Hyper(h["lambda_w"], np.array(h["beta"]), h["lambda_n"], h["mean"]) for h in meta["hyperparameters"]]
        fields = ("lower", "upper", "mean", "scale", "basis", "residual_cov", "x_train", "y_train")
        return cls(*(arrays[f"{prefix}{k}"] for k in fields), hypers, EmulatorSettings(**meta["settings"]),
                   arrays[f"{prefix}sd_factor"], [Switch(**sw) for sw in meta["switches"]],
                   ErrorModel.from_json(meta["error"]),
                   None if meta["variance"] is None else VarianceModel.from_saved(meta["variance"], arrays, prefix),
                   meta["sd_groups"])

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
            raise InputError(f"{path}: format {header.get('format')!r} version {header.get('version')}; this "
                             f"shockcal reads PC-GP emulators of version {FORMAT_VERSION} (5: the smooth sd "
                             f"model): refit it")
        return cls.from_saved(header, arrays)


def _component_count(singular_values: np.ndarray, n_components: float) -> int:
    """An integer count, or the fewest components explaining a variance fraction in (0, 1)."""
    if n_components >= 1:
        return int(min(n_components, len(singular_values)))
    explained = np.cumsum(singular_values**2) / np.sum(singular_values**2)
    return int(np.searchsorted(explained, n_components) + 1)
