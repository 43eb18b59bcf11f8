"""An external run's output read and checked: a trace file, or a features row.

Each check that fails raises `OutputError` whose message is the failed run's reason; it starts with
its kind ("output missing", "output empty", "output unparseable", "output non-finite", "output
truncated", "output units"), the part the failure budget counts runs by. A trace is read with the
units its spec declares and converted to us and m/s; a features row is in us and m/s.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Literal

import numpy as np
import pandas as pd
from pydantic import model_validator

from shockcal.io import text_encoding
from shockcal.plausibility import OTHER_UNITS, PLATEAU_RATIO, feature_problems
from shockcal.settings_model import SettingsError, SettingsModel, setting
from shockcal.units import VELOCITY_TO_M_S
from shockcal.velocimetry.columns import COLUMNS

TIME_TO_US = {"us": 1.0, "ns": 1.0e-3, "ms": 1.0e3, "s": 1.0e6}
MIN_TRACE_POINTS = 50


class OutputError(Exception):
    """A run's output is unusable; the message is the failed run's reason."""


class OutputSpec(SettingsModel):
    """What an external run writes in its folder (the config's `simulator.command.output`, and an archive's
    `simulator.archive.trace`): each field's default and description once, the schema's `run_output` generated
    from them. Checked on creation by `output_problem`, the config's rule too: a SettingsError naming the field."""

    kind: Literal["trace", "features"] = setting(
        "trace", "trace (time and velocity columns) or features (one row of the ten features, us and m/s).")
    file: str = setting("trace.csv", "The output file's name in the run's folder (CSV; `#` lines are comments).")
    time_column: str | None = setting(None, "A trace's time column (its header name); required for a trace.",
                                      optional=True, min_length=1)
    time_unit: Literal[tuple(TIME_TO_US)] = setting("us", "Unit of the time column.")
    velocity_column: str | None = setting(
        None, "A trace's free-surface velocity column (its header name); required for a trace.", optional=True,
        min_length=1)
    velocity_unit: Literal[tuple(VELOCITY_TO_M_S)] = setting("m/s", "Unit of the velocity column.")

    @model_validator(mode="after")
    def _trace_names_its_columns(self):
        found = output_problem(self.model_dump())
        if found:
            raise SettingsError(f"OutputSpec.{found[0]}: {found[1]}", *found)
        return self


def output_problem(spec: Mapping) -> tuple[str, str] | None:
    """(key, what is wrong) with an output spec, or None: a trace names its columns (the kind and the units are
    `OutputSpec`'s types)."""
    for column, unit, default in (("time_column", "time_unit", "us"), ("velocity_column", "velocity_unit", "m/s")):
        if spec.get("kind", "trace") == "trace" and not spec.get(column):
            return column, (f"missing; a trace output names its {column.split('_')[0]} column (and its unit, {unit}: "
                            f"default {default})")
    return None


def read_output(path: Path, spec: OutputSpec, window_end_us: float, impact_velocity_m_s: float) -> dict:
    """The run's output at `path`: {"t_us", "v_m_s"} arrays for a trace, or the ten features for a
    features row; OutputError (the reason) when it is unusable. A trace must reach `window_end_us` (the
    latest end of the shot's analysis window, us) and peak near `impact_velocity_m_s` (m/s)."""
    table = _read_csv(path)
    if spec.kind == "features":
        return _features(table, path)
    columns = {spec.time_column: TIME_TO_US[spec.time_unit], spec.velocity_column: VELOCITY_TO_M_S[spec.velocity_unit]}
    missing = [c for c in columns if c not in table.columns]
    if missing:
        raise OutputError(f"output unparseable: {path.name}: no column {missing[0]!r} (found {list(table.columns)})")
    t, v = (_numbers(table[c], path, c) * factor for c, factor in columns.items())
    check_trace(t, v, path.name, window_end_us, impact_velocity_m_s)
    return {"t_us": t, "v_m_s": v}


def check_trace(t_us: np.ndarray, v_m_s: np.ndarray, source: str, window_end_us: float,
                impact_velocity_m_s: float) -> None:
    """OutputError when a trace (us, m/s) has non-finite values, too few points, a time that does not
    increase, stops before `window_end_us` (us), or has a peak velocity outside `PLATEAU_RATIO` x the run's
    impact velocity (m/s; the reason names the unit it would fit, `shockcal.plausibility.OTHER_UNITS`)."""
    bad = ~(np.isfinite(t_us) & np.isfinite(v_m_s))
    if bad.any():
        raise OutputError(f"output non-finite: {source}: {int(bad.sum())} NaN, infinite or missing values, the first "
                          f"at data row {int(np.argmax(bad))}")
    if len(t_us) < MIN_TRACE_POINTS:
        raise OutputError(f"output truncated: {source}: {len(t_us)} points; at least {MIN_TRACE_POINTS} are needed")
    if np.any(np.diff(t_us) <= 0):
        raise OutputError(f"output unparseable: {source}: time does not increase at data row "
                          f"{int(np.argmax(np.diff(t_us) <= 0)) + 1}")
    if t_us[-1] < window_end_us:
        raise OutputError(f"output truncated: {source}: the trace stops at {t_us[-1]:.4g} us, before the analysis "
                          f"window's latest end {window_end_us:.4g} us")
    peak = float(np.max(v_m_s))
    low, high = (ratio * impact_velocity_m_s for ratio in PLATEAU_RATIO)
    if not low <= peak <= high:
        fits = [(unit, size) for unit, size in OTHER_UNITS["m/s"].items() if low <= peak * size <= high]
        hint = "".join(f"; it fits if the velocities are in {unit} ({peak:.4g} {unit} = {peak * size:.4g} m/s): declare "
                       "their unit (velocity_unit)" for unit, size in fits[:1])
        raise OutputError(f"output units: {source}: peak velocity {peak:.4g} m/s is outside {PLATEAU_RATIO[0]:g}-"
                          f"{PLATEAU_RATIO[1]:g} x the run's impact velocity {impact_velocity_m_s:.4g} m/s (a symmetric "
                          f"impact's free surface moves at about the impact velocity){hint}")


def _read_csv(path: Path) -> pd.DataFrame:
    if not path.is_file():
        raise OutputError(f"output missing: {path.name} was not written")
    if path.stat().st_size == 0:
        raise OutputError(f"output empty: {path.name} has no bytes")
    try:
        table = pd.read_csv(path, comment="#", encoding=text_encoding(path), sep=None, engine="python",
                            skipinitialspace=True)
    except Exception as exc:  # pandas raises many types for a broken file; all mean "unparseable"
        reason = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise OutputError(f"output unparseable: {path.name}: {reason}") from None
    if table.empty:
        raise OutputError(f"output empty: {path.name} has a header and no data rows")
    table.columns = [str(c).strip() for c in table.columns]
    return table


def _numbers(column: pd.Series, path: Path, name: str) -> np.ndarray:
    values = pd.to_numeric(column, errors="coerce")
    text = values.isna() & column.notna()
    if text.any():
        row = int(np.argmax(text.to_numpy()))
        raise OutputError(f"output unparseable: {path.name}: {name} = {column.iloc[row]!r} at data row {row} is not a number")
    return values.to_numpy(dtype=float)


def _features(table: pd.DataFrame, path: Path) -> dict:
    missing = [c for c in COLUMNS if c not in table.columns]
    if missing:
        raise OutputError(f"output unparseable: {path.name}: no feature column(s) {missing} (found {list(table.columns)})")
    if len(table) != 1:
        raise OutputError(f"output unparseable: {path.name}: {len(table)} rows; a features output is one row")
    return check_features({c: _numbers(table[c], path, c)[0] for c in COLUMNS}, path.name)


def check_features(row: dict, source: str) -> dict:
    """The ten features of one run as floats (us, m/s); OutputError when one is not finite or their
    magnitudes look like other units (`shockcal.plausibility.feature_problems`)."""
    values = {c: float(row[c]) for c in COLUMNS}
    bad = [c for c, value in values.items() if not np.isfinite(value)]
    if bad:
        raise OutputError(f"output non-finite: {source}: {', '.join(bad)}")
    problems = feature_problems(values)
    if problems:
        raise OutputError(f"output units: {source}: {'; '.join(problems)} (features are in us and m/s)")
    return values
