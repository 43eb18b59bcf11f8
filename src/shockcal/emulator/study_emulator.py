"""The study's emulator of the calibration features: design columns mapped onto PC-GP emulators.

`fit_emulator(design, features, spec)` joins each shot's features (`shockcal.velocimetry.features`) to the design on `run` and
fits one array-level `PCGPEmulator` (`shockcal.emulator.pcgp`) per block, in one of two structures (config `emulator.structure`):
- `per_shot`: one emulator per shot over that shot's own inputs (A, B, C, n, m, V_i, G_i), with G_i the sum of its shear-modulus
  inputs (SPEC section 3); shots are independent.
- `joint`: the paper's single emulator of all shots' features over all inputs.
A shot in `EmulatorSpec.own_blocks` (a new shot with runs of its own) gets a block of its own in either; a
block's inputs derive from design columns by an `InputMap` (`shockcal.emulator.input_map`).

Saved as `emulator.npz` (arrays) + `emulator.json` (format version, structure, names, units, settings, hyperparameters); loading
rebuilds the Cholesky factors: small files, no live object pickled.
"""

from __future__ import annotations

import json
import logging
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from shockcal.design.tables import ShotMapping
from shockcal.emulator.error_model import ErrorModel
from shockcal.emulator.held_out import Z90
from shockcal.emulator.input_map import InputMap, joint_input_map, shot_input_map
from shockcal.emulator.pcgp import FORMAT_VERSION, PCGPEmulator, Switch
from shockcal.emulator.settings import EmulatorSettings
from shockcal.emulator.yield_input import YieldInput
from shockcal.errors import InputError, shown
from shockcal.io import atomic_path
from shockcal.plausibility import outside_box
from shockcal.seeds import stream_seed
from shockcal.velocimetry.columns import CALIBRATION_FEATURES
from shockcal.velocimetry.feature_tables import reason_kind

log = logging.getLogger("shockcal.emulator.study_emulator")


@dataclass(frozen=True)
class EmulatorSpec:
    """What the study's emulator is fitted over: its structure (`per_shot` or `joint`), how each shot
    reads the design, the prior box by design input (native units), the extra power inputs (base,
    design column; `InputMap`), the GP settings, whose seed keys each block's own random stream, and the
    shots fitted on a block of their own in either structure (`own_blocks`: a new shot whose runs are not
    the other shots' rows, `design.new_shots`), and the law's yield stress as a last input (`yield_input`,
    config `emulator.yield_input`) or None."""

    structure: str
    shots: Mapping[str, ShotMapping]
    bounds: Mapping[str, tuple[float, float]]
    powers: tuple[tuple[float, str], ...] = ()
    settings: EmulatorSettings = field(default_factory=EmulatorSettings)
    own_blocks: tuple[str, ...] = ()
    yield_input: YieldInput | None = None


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
        self.source = "the emulator"     # its directory, once loaded (for messages)
        for block in blocks:             # the array emulator's inputs by name: the map's, then base^column
            block.model._input_names = [*block.input_map.names, *(f"{base:g}^{column}" for base, column in block.input_map.powers),
                                        *([YieldInput.name] if block.input_map.yield_input else [])]

    def __repr__(self) -> str:
        blocks = "; ".join(f"{'+'.join(b.shots)}: {len(b.runs)} runs, inputs {b.model.input_names}, "
                           f"{len(b.model.gps)} components" for b in self.blocks)
        return f"Emulator({self.structure}, shots {self.shots}, features {self.feature_names}; {blocks})"

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

    def training_features(self, shot: str) -> pd.DataFrame:
        """The training runs' calibration features of `shot` (m/s; a row per run, indexed by run id)."""
        self._check_shots([shot])
        block = next(b for b in self.blocks if shot in b.shots)
        k = len(self.feature_names)
        start = k * block.shots.index(shot)
        return pd.DataFrame(block.model.y_train[:, start:start + k], columns=self.feature_names,
                            index=pd.Index(block.runs, name="run"))

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
        """Read a saved emulator, refusing other formats, versions and feature sets, and damaged files
        (truncated, empty, not JSON, arrays missing), with a one-line message naming the file."""
        directory = Path(directory)
        meta_path, npz_path = directory / "emulator.json", directory / "emulator.npz"
        if not meta_path.is_file() or not npz_path.is_file():
            raise InputError(f"{directory}: not an emulator directory (emulator.json + emulator.npz expected)")
        refit = "refit it with `shockcal emulate` (snakemake reruns the emulator when its files are deleted)"
        try:
            meta = json.loads(meta_path.read_text())
        except (ValueError, UnicodeDecodeError) as exc:      # JSONDecodeError is a ValueError
            raise InputError(f"{meta_path}: not a readable emulator description ({exc}): truncated or damaged? "
                             f"{refit}") from None
        if not isinstance(meta, dict) or meta.get("format") != "shockcal-emulator" or meta.get("version") != FORMAT_VERSION:
            meta = meta if isinstance(meta, dict) else {}
            raise InputError(f"{meta_path}: emulator format {meta.get('format')!r} version {meta.get('version')}; "
                             f"this shockcal reads version {FORMAT_VERSION}: {refit}")
        if meta.get("feature_names") != list(cls.feature_names):
            raise InputError(f"{meta_path}: the emulator predicts features {meta.get('feature_names')}; this shockcal "
                             f"calibrates {list(cls.feature_names)}: {refit}")
        try:
            with np.load(npz_path) as npz:
                arrays = dict(npz)
        except Exception as exc:  # zipfile, OSError, ValueError, EOFError: all mean a damaged file
            raise InputError(f"{npz_path}: not a readable emulator array file ({type(exc).__name__}: "
                             f"{str(exc).splitlines()[0] if str(exc) else ''}): truncated or damaged? {refit}") from None
        try:
            blocks = [Block(InputMap.from_json(b["inputs"]), b["shots"], arrays[f"block{i}/runs"],
                            PCGPEmulator.from_saved(b, arrays, f"block{i}/")) for i, b in enumerate(meta["blocks"])]
            emulator = cls(meta["structure"], blocks, {k: tuple(v) for k, v in meta["input_bounds"].items()},
                           meta["shot_inputs"])
        except Exception as exc:  # a key or an array missing, wrong shapes: the two files do not belong together
            raise InputError(f"{directory}: emulator.json and emulator.npz do not make an emulator "
                             f"({type(exc).__name__}: {exc}): {refit}") from None
        emulator.source = str(directory)
        return emulator

    def check_study(self, shot_inputs: Mapping[str, list[str]], bounds: Mapping[str, tuple[float, float]],
                    label: str = "the emulator") -> None:
        """Refuse to serve a study that reads the design differently from the one the emulator was fitted
        for: a shot of both whose inputs differ (`shots.<shot>` velocity or shear-modulus inputs), or an
        input whose prior box reaches outside the emulator's (a narrower box is fine: it lies inside).
        Each is an InputError naming the shot or input and both sides.

        Args:
            shot_inputs: shot -> the design inputs the study maps onto it (`ShotMapping.inputs`).
            bounds: the study's prior box by input (native units).
            label: names the emulator (its directory) in messages.
        """
        for shot in [s for s in self.shots if s in shot_inputs]:
            if list(self._shot_inputs[shot]) != list(shot_inputs[shot]):
                raise InputError(f"{label}: shot {shot} reads the inputs {list(self._shot_inputs[shot])} in the "
                                 f"emulator and {list(shot_inputs[shot])} in the config (shots.{shot}); refit the "
                                 "emulator for this config")
        for name in [k for k in self._bounds if k in bounds]:
            (low, high), (lo, hi) = self._bounds[name], bounds[name]
            if outside_box([lo, hi], low, high).any():
                raise InputError(f"{label}: the prior box inputs.{name} = [{lo:g}, {hi:g}] is not inside the box the "
                                 f"emulator was fitted on [{low:g}, {high:g}]; refit the emulator on this box")

    def check_inside(self, design: pd.DataFrame, source: str) -> None:
        """An InputError naming `source`, the run and both values when a design row lies outside the box
        the emulator was fitted on (its predictions there are extrapolations)."""
        for name, (low, high) in self._bounds.items():
            if name not in design:
                continue
            values = design[name].to_numpy(dtype=float)
            outside = outside_box(values, low, high)
            if outside.any():
                first = int(np.argmax(outside))
                raise InputError(f"{source}: run {design['run'].iloc[first]}: {name} = {values[first]:g} is outside the "
                                 f"box the emulator was fitted on [{low:g}, {high:g}] ({int(outside.sum())} of "
                                 f"{len(values)} runs)")


def training_data(design: pd.DataFrame, features: pd.DataFrame, shot: str, source: str) -> pd.DataFrame:
    """Join one shot's features to the design on `run`; drop failed or NaN runs with a logged count.
    Run ids must be whole numbers (1.0 reads as 1) and unique, feature values numbers or empty."""
    from shockcal.io import check_unique, integer_ids, require_columns

    require_columns(features, ["run", *CALIBRATION_FEATURES], source)
    if features.empty:
        raise InputError(f"{source}: no runs (a features table with no rows)")
    features = integer_ids(features, "run", source)
    check_unique(features, "run", source, "run")
    for column in CALIBRATION_FEATURES:
        values = pd.to_numeric(features[column], errors="coerce")
        text = values.isna() & features[column].notna()
        if text.any():
            row = int(np.argmax(text.to_numpy()))
            raise InputError(f"{source}: row {row} (run {features['run'].iloc[row]}): {column} = "
                             f"{shown(features[column].iloc[row])} is not a number")
        features = features.assign(**{column: values.astype(float)})
    unknown = sorted(set(features["run"]) - set(design["run"]))
    if unknown:
        raise InputError(f"{source}: runs {unknown[:5]} of shot {shot} are not in the design")
    usable = features[CALIBRATION_FEATURES].notna().all(axis=1)
    if "status" in features.columns:
        usable &= features["status"].eq("ok")
    dropped = int((~usable).sum())
    if dropped:
        reasons = (features.loc[~usable, "reason"].astype(str).map(reason_kind).value_counts()
                   if "reason" in features.columns else {})
        log.info("shot %s: %d of %d runs dropped (failed or NaN features)%s", shot, dropped, len(features),
                 "".join(f"; {kind}: {count}" for kind, count in reasons.items()))
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
                 sources: dict[str, str] | None = None,
                 shot_designs: Mapping[str, pd.DataFrame] | None = None) -> Emulator:
    """Fit the study's emulator; block i fits with stream ("emulator", i) of `spec.settings.seed`.

    Args:
        design: design table (`run` and the inputs, Table IV units).
        features: shot -> its features table (`run`, `status`, the calibration features in m/s),
            joined to the design on `run`; failed or NaN runs are dropped with a logged count.
        spec: structure, shot mappings, prior box, power inputs and GP settings (`EmulatorSpec`).
        sources: shot -> where its table came from, for messages.
        shot_designs: shot -> a design of its own (a shot of `spec.own_blocks`), joined to its features
            instead of `design`.
    """
    shots = list(features)
    unmapped = [shot for shot in shots if shot not in spec.shots]
    if unmapped:
        raise InputError(f"features of shots {unmapped}: the emulator spec maps only {list(spec.shots)}")
    mappings = [spec.shots[shot] for shot in shots]
    sources = sources or {shot: f"features of {shot}" for shot in shots}
    shot_designs = shot_designs or {}
    tables = {shot: training_data(shot_designs.get(shot, design), features[shot], shot, sources[shot]) for shot in shots}
    together = [m for m in mappings if m.shot not in spec.own_blocks]
    groups = []
    if spec.structure == "joint" and together:
        names = [m.shot for m in together]
        joined = tables[names[0]].rename(columns={f: f"{names[0]}:{f}" for f in CALIBRATION_FEATURES})
        for shot in names[1:]:
            joined = joined.merge(tables[shot][["run", *CALIBRATION_FEATURES]].rename(
                columns={f: f"{shot}:{f}" for f in CALIBRATION_FEATURES}), on="run", how="inner")
        groups.append((names, joint_input_map(together, spec.bounds, spec.powers), joined, "joint training set",
                       [f"{s}:{f}" for s in names for f in CALIBRATION_FEATURES]))
    groups += [([m.shot], shot_input_map(m, spec.bounds, spec.powers), tables[m.shot], sources[m.shot],
                CALIBRATION_FEATURES) for m in mappings if spec.structure == "per_shot" or m.shot in spec.own_blocks]
    blocks = []
    for i, (block_shots, input_map, table, label, columns) in enumerate(groups):
        _check_training_inputs(table, input_map, label)
        if spec.yield_input is not None:
            input_map = input_map.with_yield(spec.yield_input, table)
        settings = spec.settings.replace(seed=stream_seed(spec.settings.seed, "emulator", i))
        model = PCGPEmulator.fit(input_map.raw(table), table[columns].to_numpy(), input_map.lower, input_map.upper,
                                 settings, switches=single_wave_switches(len(block_shots)),
                                 sd_groups=feature_groups(len(block_shots)))
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


def feature_groups(n_shots: int) -> list[list[int]]:
    """Groups of output columns sharing one smooth variance model (`shockcal.emulator.variance_model`): each
    calibration feature across the shots (features in CALIBRATION_FEATURES order, shot after shot).
    A feature's error grows in the same corners of the box in every shot (FLAG runs 0-499), and pooling
    the shots thins the noise of log z^2; one model per output fitted worse (docs/emulator.md)."""
    k = len(CALIBRATION_FEATURES)
    return [[k * i + f for i in range(n_shots)] for f in range(k)]


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
