"""Principal-component Gaussian-process emulator of the calibration features (SPEC section 5).

Features y (m/s) of each training run are standardized per feature (mean vector, sd vector),
projected on an orthogonal basis from the SVD of the standardized training outputs, and each basis
weight gets its own GP (`shockcal.gp`) over inputs scaled to [0, 1] by the prior box. Prediction
returns the mean and covariance in feature space (m/s), adding the covariance of what the
truncated basis leaves out (the training residuals' covariance).

Two structures (config `emulator.structure`):
- `per_shot`: one emulator per shot over that shot's own inputs (A, B, C, n, m, V_i, G_i), with
  G_i the sum of its shear-modulus inputs (SPEC section 3); shots are independent.
- `joint`: the paper's single emulator of all shots' features over all inputs.

Saved as `emulator.npz` (arrays) + `emulator.json` (format version, structure, names, units,
hyperparameters); loading rebuilds the Cholesky factors, so files stay small and no live object
is pickled.
"""

from __future__ import annotations

import json
import logging
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from shockcal.config import STRENGTH_INPUTS, shot_config
from shockcal.errors import InputError
from shockcal.gp import GaussianProcess, Hyper

FORMAT_VERSION = 1
CALIBRATION_FEATURES = ["v_elastic", "v_plastic", "v_slope1", "v_slope2"]
log = logging.getLogger("shockcal.emulator")


@dataclass
class InputMap:
    """How one emulator's inputs derive from design inputs: each is a sum of design columns."""

    names: list[str]            # emulator input names, e.g. [A, B, C, n, m, V2, G_105S]
    terms: list[list[str]]      # design columns summed into each input
    lower: np.ndarray           # box of each input (sum of the terms' bounds)
    upper: np.ndarray

    def design_inputs(self) -> list[str]:
        return list(dict.fromkeys(t for terms in self.terms for t in terms))

    def scaled(self, inputs) -> np.ndarray:
        """(N, d) inputs scaled to [0, 1] from a mapping or DataFrame of design columns."""
        raw = np.column_stack([sum(np.asarray(inputs[t], dtype=float) for t in terms) for terms in self.terms])
        return (raw - self.lower) / (self.upper - self.lower)

    def to_json(self) -> dict:
        return {"names": self.names, "terms": self.terms, "lower": self.lower.tolist(), "upper": self.upper.tolist()}

    @classmethod
    def from_json(cls, d: dict) -> "InputMap":
        return cls(d["names"], d["terms"], np.array(d["lower"]), np.array(d["upper"]))


def shot_input_map(config: dict, shot: str) -> InputMap:
    """A per-shot emulator's inputs: A, B, C, n, m, the shot's velocity, its summed shear modulus."""
    spec = shot_config(config, shot)
    terms = [[k] for k in STRENGTH_INPUTS] + [[spec["velocity_input"]], list(spec["shear_modulus_inputs"])]
    names = [*STRENGTH_INPUTS, spec["velocity_input"], f"G_{shot}"]
    return _box_map(config, names, terms)


def joint_input_map(config: dict, shots: list[str]) -> InputMap:
    """The joint emulator's inputs: every design input the shots use, each on its own."""
    used = list(dict.fromkeys(k for shot in shots for k in _shot_terms(config, shot)))
    return _box_map(config, used, [[k] for k in used])


def _shot_terms(config, shot):
    spec = shot_config(config, shot)
    return [*STRENGTH_INPUTS, spec["velocity_input"], *spec["shear_modulus_inputs"]]


def _box_map(config, names, terms) -> InputMap:
    lower = np.array([sum(config["inputs"][t]["min"] for t in ts) for ts in terms])
    upper = np.array([sum(config["inputs"][t]["max"] for t in ts) for ts in terms])
    return InputMap(names, terms, lower, upper)


class PCEmulator:
    """GP emulator of a block of features (one shot's, or all shots') on a principal-component basis."""

    def __init__(self, input_map: InputMap, shots: list[str], mean, scale, basis, residual_cov,
                 x_train, y_train, runs, hypers: list[Hyper]):
        self.input_map, self.shots = input_map, shots
        self.mean, self.scale, self.basis = np.asarray(mean), np.asarray(scale), np.asarray(basis)
        self.residual_cov = np.asarray(residual_cov)
        self.x_train, self.y_train, self.runs = np.asarray(x_train), np.asarray(y_train), np.asarray(runs)
        self.weights = self.project((self.y_train - self.mean) / self.scale)
        self.gps = [GaussianProcess(self.x_train, self.weights[:, j], h) for j, h in enumerate(hypers)]

    def project(self, z: np.ndarray) -> np.ndarray:
        """Basis weights of standardized outputs z (least squares on the orthogonal basis)."""
        return z @ self.basis.T / np.sum(self.basis**2, axis=1)

    @classmethod
    def fit(cls, input_map: InputMap, shots: list[str], x_design: pd.DataFrame, y: np.ndarray, runs,
            n_components: float, n_starts: int, seed: int, max_fit_runs: int) -> "PCEmulator":
        """Standardize y (N, F), build the basis, fit one GP per weight at its MAP."""
        x = input_map.scaled(x_design)
        mean, scale = y.mean(0), y.std(0)
        scale = np.where(scale > 0, scale, 1.0)
        z = (y - mean) / scale
        u, s, vt = np.linalg.svd(z, full_matrices=False)
        p = _component_count(s, n_components)
        n = len(y)
        weights = u[:, :p] * np.sqrt(n)                   # unit-variance weights
        basis = vt[:p] * (s[:p, None] / np.sqrt(n))       # z ~ weights @ basis
        residual = z - weights @ basis
        residual_cov = residual.T @ residual / n
        rng = np.random.default_rng(seed)
        fit_rows = None if n <= max_fit_runs else np.sort(rng.choice(n, max_fit_runs, replace=False))
        hypers = [GaussianProcess.fit(x, weights[:, j], n_starts=n_starts, seed=seed + j, fit_rows=fit_rows).hyper
                  for j in range(p)]
        log.info("emulator %s: %d runs, %d inputs, %d of %d components (%.4f of variance)",
                 "+".join(shots), n, x.shape[1], p, len(s), (s[:p] ** 2).sum() / (s**2).sum())
        return cls(input_map, shots, mean, scale, basis, residual_cov, x, y, runs, hypers)

    def predict_scaled(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Mean (N, F) and covariance (N, F, F) in m/s at scaled inputs x (N, d)."""
        w_mean = np.empty((len(x), len(self.gps)))
        w_var = np.empty_like(w_mean)
        for j, gp in enumerate(self.gps):
            w_mean[:, j], w_var[:, j] = gp.predict(x)
        z_cov = np.einsum("nj,jf,jg->nfg", w_var, self.basis, self.basis) + self.residual_cov
        mean = self.mean + (w_mean @ self.basis) * self.scale
        return mean, z_cov * np.outer(self.scale, self.scale)

    def loo(self) -> tuple[np.ndarray, np.ndarray]:
        """Closed-form leave-one-out mean (N, F) and sd (N, F) in m/s, hyperparameters and basis fixed."""
        w_mean = np.empty_like(self.weights)
        w_var = np.empty_like(self.weights)
        for j, gp in enumerate(self.gps):
            w_mean[:, j], w_var[:, j] = gp.loo()
        z_var = w_var @ self.basis**2 + np.diag(self.residual_cov)
        return self.mean + (w_mean @ self.basis) * self.scale, np.sqrt(z_var) * self.scale

    def to_arrays(self, prefix: str) -> dict:
        arrays = {"mean": self.mean, "scale": self.scale, "basis": self.basis, "residual_cov": self.residual_cov,
                  "x_train": self.x_train, "y_train": self.y_train, "runs": self.runs}
        return {f"{prefix}/{k}": v for k, v in arrays.items()}

    def to_json(self) -> dict:
        return {"shots": self.shots, "inputs": self.input_map.to_json(),
                "hyperparameters": [{"lambda_w": g.hyper.lambda_w, "beta": g.hyper.beta.tolist(),
                                     "lambda_n": g.hyper.lambda_n} for g in self.gps]}

    @classmethod
    def from_saved(cls, meta: dict, arrays, prefix: str) -> "PCEmulator":
        hypers = [Hyper(h["lambda_w"], np.array(h["beta"]), h["lambda_n"]) for h in meta["hyperparameters"]]
        fields = ("mean", "scale", "basis", "residual_cov", "x_train", "y_train", "runs")
        return cls(InputMap.from_json(meta["inputs"]), meta["shots"], *(arrays[f"{prefix}/{k}"] for k in fields), hypers)


def _component_count(singular_values: np.ndarray, n_components: float) -> int:
    """An integer count, or the fewest components explaining a variance fraction in (0, 1)."""
    if n_components >= 1:
        return int(min(n_components, len(singular_values)))
    explained = np.cumsum(singular_values**2) / np.sum(singular_values**2)
    return int(np.searchsorted(explained, n_components) + 1)


class Emulator:
    """The study's emulator: one PCEmulator per shot (per_shot) or one for all shots (joint)."""

    feature_names = CALIBRATION_FEATURES

    def __init__(self, structure: str, blocks: list[PCEmulator], bounds: dict, shot_inputs: dict):
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
            m, c = block.predict_scaled(block.input_map.scaled(self._complete(inputs, block, n)))
            src = np.concatenate([np.arange(k) + k * block.shots.index(s) for s in wanted])
            dst = np.concatenate([np.arange(k) + k * shots.index(s) for s in wanted])
            mean[:, dst] = m[:, src]
            cov[:, dst[:, None], dst[None, :]] = c[:, src[:, None], src[None, :]]
        return mean, cov

    def _complete(self, inputs, block: PCEmulator, n: int) -> dict:
        """The block's design inputs, those not given held at mid-box."""
        return {t: np.asarray(inputs[t], dtype=float) if t in inputs else np.full(n, np.mean(self._bounds[t]))
                for t in block.input_map.design_inputs()}

    def _check_shots(self, shots):
        missing = [s for s in shots if s not in self.shots]
        if missing:
            raise InputError(f"the emulator has no shot {missing}; it was fitted for {self.shots}")

    def cv_table(self) -> pd.DataFrame:
        """Leave-one-out table: run, shot, feature, simulated, predicted, predicted_sd (m/s)."""
        k = len(self.feature_names)
        parts = []
        for block in self.blocks:
            loo_mean, loo_sd = block.loo()
            for i, shot in enumerate(block.shots):
                for f, feature in enumerate(self.feature_names):
                    col = k * i + f
                    parts.append(pd.DataFrame({"run": block.runs, "shot": shot, "feature": feature,
                                               "simulated": block.y_train[:, col], "predicted": loo_mean[:, col],
                                               "predicted_sd": loo_sd[:, col]}))
        return pd.concat(parts, ignore_index=True)

    def save(self, directory) -> Path:
        """Write emulator.npz (arrays) and emulator.json (version, names, hyperparameters)."""
        directory = Path(directory)
        directory.mkdir(parents=True, exist_ok=True)
        arrays = {}
        for i, block in enumerate(self.blocks):
            arrays.update(block.to_arrays(f"block{i}"))
        np.savez(directory / "emulator.npz", **arrays)
        meta = {"format": "shockcal-emulator", "version": FORMAT_VERSION, "structure": self.structure,
                "feature_names": self.feature_names, "feature_units": "m/s",
                "input_bounds": {k: list(v) for k, v in self._bounds.items()},
                "shot_inputs": self._shot_inputs, "blocks": [b.to_json() for b in self.blocks]}
        (directory / "emulator.json").write_text(json.dumps(meta, indent=1))
        return directory

    @classmethod
    def load(cls, directory) -> "Emulator":
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
        blocks = [PCEmulator.from_saved(b, arrays, f"block{i}") for i, b in enumerate(meta["blocks"])]
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


def fit_emulator(config: dict, design: pd.DataFrame, features: dict[str, pd.DataFrame],
                 sources: dict[str, str] | None = None) -> Emulator:
    """Fit the configured emulator structure to design + per-shot feature tables."""
    settings = config["emulator"]
    shots = list(features)
    sources = sources or {shot: f"features of {shot}" for shot in shots}
    tables = {shot: training_data(design, features[shot], shot, sources[shot]) for shot in shots}
    common = dict(n_components=settings["n_components"], n_starts=settings["n_starts"],
                  max_fit_runs=settings["max_fit_runs"])
    seed = config["study"]["seed"]
    if settings["structure"] == "per_shot":
        blocks = []
        for i, shot in enumerate(shots):
            input_map = shot_input_map(config, shot)
            _check_training_inputs(tables[shot], input_map, sources[shot])
            blocks.append(PCEmulator.fit(input_map, [shot], tables[shot], tables[shot][CALIBRATION_FEATURES].to_numpy(),
                                         tables[shot]["run"].to_numpy(), seed=seed + 100 * i, **common))
    else:
        joined = tables[shots[0]].rename(columns={f: f"{shots[0]}:{f}" for f in CALIBRATION_FEATURES})
        for shot in shots[1:]:
            joined = joined.merge(tables[shot][["run", *CALIBRATION_FEATURES]].rename(
                columns={f: f"{shot}:{f}" for f in CALIBRATION_FEATURES}), on="run", how="inner")
        input_map = joint_input_map(config, shots)
        _check_training_inputs(joined, input_map, "joint training set")
        y = joined[[f"{s}:{f}" for s in shots for f in CALIBRATION_FEATURES]].to_numpy()
        blocks = [PCEmulator.fit(input_map, shots, joined, y, joined["run"].to_numpy(), seed=seed, **common)]
    bounds = {k: (v["min"], v["max"]) for k, v in config["inputs"].items()}
    return Emulator(settings["structure"], blocks, bounds, {s: _shot_terms(config, s) for s in shots})


def rmse_table(cv: pd.DataFrame) -> pd.DataFrame:
    """Per shot and feature: LOO RMSE, bias (m/s) and 90%-band coverage, plus an overall row."""
    err = cv["predicted"] - cv["simulated"]
    inside = (err.abs() <= 1.6449 * cv["predicted_sd"])
    frame = cv.assign(sq=err**2, err=err, inside=inside)
    per = frame.groupby(["shot", "feature"], sort=False).agg(rmse_m_s=("sq", "mean"), bias_m_s=("err", "mean"),
                                                              coverage90=("inside", "mean")).reset_index()
    per["rmse_m_s"] = np.sqrt(per["rmse_m_s"])
    overall = pd.DataFrame([{"shot": "all", "feature": "all", "rmse_m_s": float(np.sqrt(frame["sq"].mean())),
                             "bias_m_s": float(err.mean()), "coverage90": float(inside.mean())}])
    return pd.concat([per, overall], ignore_index=True).round(3)
