"""Finished runs as a run source: one shot's rows of a design looked up in an archive (docs/simulators.md).

An archive gives, per shot, a features table (`run` and the ten features, us and m/s: e.g. FLAG's
runs in the paper's data release) or one trace file per run (a path pattern with `{run}`, read and
checked as an external code's output, `shockcal.simulators.outputs`). The table has builtin's columns
(`shockcal.simulators.builtin`; diagnostics NaN); a features archive adds the ten feature columns and
empty traces. A run the archive lacks, or whose values are unusable, is a failed row with its reason.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from shockcal.design.tables import ShotMapping
from shockcal.errors import InputError
from shockcal.simulators.builtin import DIAGNOSTICS, simulation_columns
from shockcal.simulators.outputs import OutputError, OutputSpec, check_features, read_output
from shockcal.velocimetry.columns import COLUMNS as FEATURE_COLUMNS

log = logging.getLogger("shockcal.simulators.archive")


@dataclass(frozen=True)
class ArchiveSource:
    """One shot's archived runs: the archive's design, and a features table or a trace-file pattern with
    `{run}` and its columns' spec."""

    design: Path
    features: Path | None = None
    traces: str | None = None
    trace: OutputSpec | None = None


def archive_design(design: pd.DataFrame, mapping: ShotMapping, source: ArchiveSource,
                   window_end_us: float) -> pd.DataFrame:
    """The archived runs of every row of `design` for one shot, one row per run.

    Args:
        design: design table (`run` and the inputs `mapping` reads, Table IV units).
        mapping: how the shot reads a design row.
        source: where the shot's runs are (`ArchiveSource`).
        window_end_us: the latest end of the shot's analysis window (us); an archived trace must reach it.
    """
    features = _features_by_run(source.features) if source.features is not None else None
    archived = _rows_by_run(source.design, mapping.inputs())
    rows = []
    for record in design.to_dict("records"):
        run = int(record["run"])
        row = {"run": run, "shot": mapping.shot, **{k: float(record[k]) for k in mapping.inputs()},
               "impact_velocity_m_s": np.nan, "shear_modulus_GPa": np.nan, "status": "ok", "reason": "",
               **dict.fromkeys(DIAGNOSTICS, np.nan), "t_us": [], "v_m_s": []}
        try:
            _check_archived_inputs(run, record, archived, mapping.inputs(), source.design)
            params = mapping.parameters(record)
            row["impact_velocity_m_s"] = params.velocity_m_s
            row["shear_modulus_GPa"] = np.nan if params.shear_modulus_GPa is None else params.shear_modulus_GPa
            row.update(_archived(run, features, source, window_end_us, params.velocity_m_s))
        except (InputError, OutputError) as exc:
            row.update(status="failed", reason=f"archive: {exc}")
            log.warning("run %s of shot %s: %s", run, mapping.shot, row["reason"])
        rows.append(row)
    table = pd.DataFrame(rows)
    table["n_steps"] = table["n_steps"].astype("Int64")
    columns = simulation_columns(mapping.inputs())
    return table[[*columns, *(c for c in FEATURE_COLUMNS if c in table.columns)]]


def _archived(run: int, features: dict | None, source: ArchiveSource, window_end_us: float,
              velocity_m_s: float) -> dict:
    if features is None:
        path = Path(source.traces.replace("{run}", str(run)))
        return read_output(path, source.trace, window_end_us, velocity_m_s)
    if run not in features:
        raise OutputError(f"output missing: no features of run {run} in {source.features}")
    return check_features(features[run], f"{source.features} run {run}")


def _check_archived_inputs(run: int, record: dict, archived: dict, inputs: list[str], path: Path) -> None:
    """OutputError unless the archive's design has run `run` with these inputs (at the rounding floor,
    rtol 1e-10): a run id of another design (a posterior draw's) would otherwise get an archived run's values."""
    if run not in archived:
        raise OutputError(f"output missing: run {run} is not in the archive's design {path}")
    given, stored = (np.array([float(row[k]) for k in inputs]) for row in (record, archived[run]))
    if not np.allclose(given, stored, rtol=1e-10, atol=0.0):
        name = inputs[int(np.argmax(~np.isclose(given, stored, rtol=1e-10, atol=0.0)))]
        raise OutputError(f"output missing: run {run} has {name} = {record[name]:.10g}, the archive's design "
                          f"{path} {archived[run][name]:.10g}: not an archived run")


def _rows_by_run(path: Path, inputs: list[str]) -> dict[int, dict]:
    """run -> its inputs, from the archive's design."""
    from shockcal.io import integer_ids, read_table, require_columns

    table = read_table(path)
    require_columns(table, ["run", *inputs], path)
    table = integer_ids(table, "run", path)
    return {int(r["run"]): r for r in table[["run", *inputs]].to_dict("records")}


def _features_by_run(path: Path) -> dict[int, dict]:
    """run -> its ten features, from an archive's features table."""
    from shockcal.io import integer_ids, read_table, require_columns

    table = read_table(path)
    require_columns(table, ["run", *FEATURE_COLUMNS], path)
    table = integer_ids(table, "run", path)
    return {int(r["run"]): {c: r[c] for c in FEATURE_COLUMNS} for r in table.to_dict("records")}
