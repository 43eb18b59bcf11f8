"""Design tables: the seeded Latin hypercube over the prior box, user designs, and the per-shot mapping.

A design table has one row per run: an integer `run` id and one column per calibration input
(A, B, C, n, m, V1, V2, V3, G1, Delta2, Delta3 for the paper's study) in the box's native units
(Mbar for A, B and shear moduli; cm/us for velocities; C, n, m dimensionless). One design serves
every shot: a `ShotMapping` maps a row onto one shot (SPEC section 3). An `InputBox` is the prior
box a design is checked against (`shockcal.study.adapters.input_box` builds it from a config).
"""

from __future__ import annotations

import logging
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from shockcal.design.settings import InputRange
from shockcal.errors import InputError, number, shown
from shockcal.hydro import LawShotParameters, ShotParameters
from shockcal.hydro.laws import DEFAULT_COLUMNS, DEFAULT_MODEL, get_law
from shockcal.io import integer_ids, read_table, require_columns
from shockcal.plausibility import outside_box, range_problem
from shockcal.settings_model import SettingsError
from shockcal.units import CM_US_TO_M_S, MBAR_TO_GPA

log = logging.getLogger("shockcal.design.tables")


@dataclass(frozen=True)
class InputBox:
    """The prior box of the calibration inputs, which a design must lie in.

    Args:
        bounds: input name -> (min, max) in the input's native unit, in the design's column order.
        units: input name -> its unit (e.g. "Mbar", "cm/us", "-"), for messages and table metadata.
        velocity_of: input name -> the shot whose impact velocity it is (names it in messages).
        strict: whether a design point outside the box stops the load (else a warning;
            config `checks.design_box`).
    """

    bounds: Mapping[str, tuple[float, float]]
    units: Mapping[str, str]
    velocity_of: Mapping[str, str] = field(default_factory=dict)
    strict: bool = True

    def __post_init__(self):
        """Each input's bounds and unit as the config's `inputs.<name>` (`InputRange`): an InputError naming it."""
        for name, (low, high) in self.bounds.items():
            try:
                InputRange(min=low, max=high, unit=self.units.get(name, ""))
            except SettingsError as exc:
                raise InputError(f"InputBox.bounds.{name}.{exc.field}: {exc.reason}") from None

    def names(self) -> list[str]:
        """The inputs in the box's order (a design table's columns after `run`)."""
        return list(self.bounds)


def latin_hypercube(bounds: Mapping[str, tuple[float, float]], n_runs: int, seed: int) -> pd.DataFrame:
    """A seeded Latin hypercube of `n_runs` points over a box (scipy.stats.qmc).

    Args:
        bounds: input name -> (min, max), native units.
        n_runs: points (runs) in the design.
        seed: the hypercube's seed.

    The hypercube's dimensions are the inputs in sorted order, so the design depends on the box and
    the seed, not on the order the box lists its inputs (the workflow's jobs read a key-sorted copy
    of the config); the columns come back in the box's order.
    """
    from scipy.stats import qmc

    names = sorted(bounds)
    lower, upper = np.array([bounds[name] for name in names], dtype=float).T
    unit = qmc.LatinHypercube(d=len(names), seed=np.random.default_rng(seed)).random(n_runs)
    design = pd.DataFrame(qmc.scale(unit, lower, upper), columns=names)[list(bounds)]
    design.insert(0, "run", np.arange(n_runs, dtype=np.int64))
    return design


def extend_design(design: pd.DataFrame, bounds: Mapping[str, tuple[float, float]], seeds: Mapping[str, int]
                  ) -> pd.DataFrame:
    """The design with one new column per input of `bounds`, each a one-dimensional Latin hypercube
    over the design's rows (scipy.stats.qmc) from its own seed; the existing columns are untouched.

    Args:
        design: design table (`run` and its inputs).
        bounds: new input name -> (min, max), native units.
        seeds: new input name -> the seed of its column.
    """
    from scipy.stats import qmc

    extended = design.copy()
    for name, (low, high) in bounds.items():
        unit = qmc.LatinHypercube(d=1, seed=np.random.default_rng(seeds[name])).random(len(design))[:, 0]
        extended[name] = low + unit * (high - low)
    return extended


def load_design(path: str | Path, box: InputBox, columns: list[str] | None = None, allow_empty: bool = False
                ) -> pd.DataFrame:
    """Read a CSV/Parquet design, check it, and return it with an integer `run` column.

    Args:
        path: the design table (one row per run; `run` is added as 0..N-1 when absent).
        box: the prior box the design must lie in (`check_design_box`).
        columns: the inputs that must be present (default: all of the box's).
        allow_empty: whether a design with no rows is fine (a sequential study's stopped wave).

    Run ids must be whole numbers (1.0 reads as 1; 1.5 is an error) and unique; values finite;
    Johnson-Cook inputs non-negative; velocities and shear moduli positive (checked per shot by
    `ShotMapping.check_positive`). No rows is an error unless `allow_empty`. Errors name the file, the row and the parameter.
    Returned: `run` and the box's inputs the file has (other columns, e.g. notes, are left out).
    """
    design = read_table(path)
    columns = box.names() if columns is None else columns
    require_columns(design, columns, path)
    if design.empty and not allow_empty:
        raise InputError(f"{path}: the design has no runs (a header and no rows)")
    if "run" not in design.columns:
        design.insert(0, "run", np.arange(len(design), dtype=np.int64))
    design = integer_ids(design, "run", path)
    if design["run"].duplicated().any():
        dup = design.loc[design["run"].duplicated(), "run"].iloc[0]
        raise InputError(f"{path}: run id {dup} appears more than once")
    for name in columns:
        values = pd.to_numeric(design[name], errors="coerce")
        bad = ~np.isfinite(values.to_numpy(dtype=float))
        if bad.any():
            row = design.loc[bad, "run"].iloc[0]
            raise InputError(f"{path}: run {row}: parameter {name} is not a finite number ({shown(design.loc[bad, name].iloc[0])})")
        design[name] = values.astype(float)
        if name in DEFAULT_COLUMNS and (values < 0).any():     # ShotParameters' rule, whatever the study's law
            row = design.loc[values < 0, "run"].iloc[0]
            raise InputError(f"{path}: run {row}: parameter {name} = {number(values[values < 0].iloc[0])} is negative")
    design["run"] = design["run"].astype(np.int64)
    check_design_box(design, box, columns, path)
    kept = ["run", *(name for name in box.names() if name in design.columns)]   # other columns: notes, not inputs
    return design[kept].reset_index(drop=True)


def check_design_box(design: pd.DataFrame, box: InputBox, columns: list[str], source) -> None:
    """Stop at the first run with an input outside the prior box, saying which unit the value would
    fit (e.g. V1 = 204: m/s, not cm/us); with `box.strict` false, warn instead."""
    for name in columns:
        low, high = box.bounds[name]
        values = design[name].to_numpy(dtype=float)
        outside = outside_box(values, low, high)
        if not outside.any():
            continue
        first = int(np.argmax(outside))
        what = (f"impact velocity {name} of shot {box.velocity_of[name]}" if name in box.velocity_of
                else f"parameter {name}")
        problem = range_problem(what, values[first], box.units[name], (low, high), f"the prior box inputs.{name}")
        message = f"{source}: run {design['run'].iloc[first]}: {problem}; {int(outside.sum())} of {len(values)} runs are outside on {name}"
        if box.strict:
            raise InputError(f"{message}. If these points are intended, set checks.design_box: false")
        log.warning("%s (accepted: checks.design_box: false)", message)


@dataclass(frozen=True)
class ShotMapping:
    """How one shot reads a design row (SPEC section 3): the input that is its impact velocity (cm/us),
    the inputs whose sum is its shear modulus (Mbar; none for a law with its own G law), and the strength
    law's inputs every shot shares, its design columns (`shockcal.hydro.laws.Law.column`): Johnson-Cook's
    A, B, C, n, m in code units (Mbar), another law's declared parameters in the units their names carry.
    The default law and its columns are the registry's (`DEFAULT_MODEL`, `DEFAULT_COLUMNS`)."""

    shot: str
    velocity_input: str
    shear_modulus_inputs: tuple[str, ...]
    model: str = DEFAULT_MODEL
    strength_inputs: tuple[str, ...] = DEFAULT_COLUMNS

    def inputs(self) -> list[str]:
        """The design columns the shot depends on: the law's inputs, its velocity, its shear-modulus terms."""
        return [*self.strength_inputs, self.velocity_input, *self.shear_modulus_inputs]

    def parameters(self, row) -> ShotParameters | LawShotParameters:
        """One design row (a mapping of input name to value) as this shot's hydrocode inputs. A law with
        code-unit columns (Johnson-Cook's Table IV values) reaches the kernel unconverted (`ShotParameters.from_table_iv`); another law's go
        through `LawShotParameters` (its material constants and constraints are checked by `run_shot`, with
        the run's material)."""
        velocity = float(row[self.velocity_input])
        shear = float(sum(row[k] for k in self.shear_modulus_inputs)) if self.shear_modulus_inputs else None
        if get_law(self.model).code_unit_columns:     # Johnson-Cook: its code-unit door
            return ShotParameters.from_table_iv(*(float(row[k]) for k in self.strength_inputs),
                                                velocity_cm_us=velocity, shear_modulus_Mbar=shear)
        return LawShotParameters(self.model, {k: float(row[k]) for k in self.strength_inputs},
                                 velocity * CM_US_TO_M_S, None if shear is None else shear * MBAR_TO_GPA)

    def check_positive(self, design: pd.DataFrame, source: str | Path) -> None:
        """Reject rows whose velocity or shear modulus is not positive for this shot, before any run starts."""
        checks = [(f"impact velocity {self.velocity_input}", design[self.velocity_input].to_numpy(dtype=float))]
        if self.shear_modulus_inputs:
            checks.append((f"shear modulus {'+'.join(self.shear_modulus_inputs)}",
                           design[list(self.shear_modulus_inputs)].to_numpy(dtype=float).sum(axis=1)))
        for label, values in checks:
            bad = values <= 0
            if bad.any():
                row = design.loc[bad, "run"].iloc[0]
                raise InputError(f"{source}: run {row}: {label} = {number(values[bad][0])} must be positive for shot {self.shot}")


def write_design(design: pd.DataFrame, source: str, box: InputBox, path: str | Path) -> bool:
    """Write a design table (run + the box's inputs, with their units and `source` in the metadata)
    unless `path` already holds the same rows and columns; True when it wrote. Same rows from another
    source (a hypercube saved as a design file) leave the file, its mtime and what depends on it
    alone; its metadata keeps the first source."""
    from shockcal.io import write_table

    table = design[["run", *box.names()]].reset_index(drop=True)
    meta = {"table": "design", "source": source, "units": {name: box.units[name] for name in box.names()}}
    path = Path(path)
    if path.is_file() and _same_table(path, table):
        return False
    write_table(table, path, meta)
    return True


def _same_table(path: Path, table: pd.DataFrame) -> bool:
    """Whether the Parquet file at `path` holds `table` (an unreadable file does not: it is rewritten)."""
    try:
        return pd.read_parquet(path).equals(table)
    except Exception:  # pyarrow raises many types for a damaged file; it is replaced either way
        return False


def chunk_fingerprints(design: pd.DataFrame, chunk_size: int) -> list[str]:
    """A content digest of each chunk of `chunk_size` design rows.

    The workflow puts these in each simulate job's params, so a chunk reruns exactly when its own
    rows change: appending runs to a design file adds chunks without touching finished ones, and
    the same rows with their columns in another order change nothing.
    """
    import hashlib

    digests = []
    for start in range(0, len(design), chunk_size):
        rows = design.iloc[start:start + chunk_size][sorted(design.columns)]    # the column order is no content
        digests.append(hashlib.sha256(pd.util.hash_pandas_object(rows, index=False).to_numpy().tobytes()).hexdigest()[:16])
    return digests
