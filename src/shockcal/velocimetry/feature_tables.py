"""Feature tables: the features of every run of a simulations table (`features_table`), of a measured record
with its read-out error (`record_features`), and the failed runs' budget (`check_failures`). The method that
reads one trace is `shockcal.velocimetry.features`.
"""

from __future__ import annotations

import logging
import re
from typing import TYPE_CHECKING

import numpy as np
from scipy import stats

from shockcal.errors import InputError, ShockcalError
from shockcal.velocimetry.columns import CALIBRATION_FEATURES, COLUMNS
from shockcal.velocimetry.features import (
    ExtractorSettings,
    FeatureError,
    extract,
    extract_features,
    readout_replicates,
)

if TYPE_CHECKING:
    import pandas as pd

log = logging.getLogger("shockcal.velocimetry.feature_tables")


def features_table(traces, settings: ExtractorSettings, source: str = "simulations", allow_empty: bool = False
                   ) -> pd.DataFrame:
    """One row per simulated run (a simulations table: run, status, reason, t_us, v_m_s): run, status,
    reason and the ten features.

    Failed simulations keep their status and reason; a trace the extractor cannot read becomes
    status "failed" with the extractor's reason. A row that carries the ten features and no trace (an
    external code's or an archive's features) keeps them as they are. A table that is not a simulations table (columns
    missing, no rows, run ids that are not whole numbers, traces that are not lists of numbers: a CSV
    copy of a chunk) is an InputError naming `source` and the run; no rows is fine with `allow_empty`
    (a sequential study's stopped wave).
    """
    import pandas as pd

    from shockcal.io import integer_ids, require_columns

    require_columns(traces, ["run", "status", "reason", "t_us", "v_m_s"], source)
    if traces.empty and not allow_empty:
        raise InputError(f"{source}: no runs (a simulations table with no rows)")
    traces = integer_ids(traces, "run", source)
    rows = []
    for record in traces.to_dict("records"):
        row = {"run": int(record["run"]), "status": record["status"], "reason": record["reason"]}
        if record["status"] == "ok" and _given_features(record):
            row.update({column: record[column] for column in COLUMNS})
        elif record["status"] == "ok":
            t, v = (_trace_column(record, column, source) for column in ("t_us", "v_m_s"))
            try:
                row.update(extract_features(t, v, settings))
            except FeatureError as exc:
                row.update(status="failed", reason=f"feature extraction: {exc}")
        rows.append(row)
    table = pd.DataFrame(rows) if rows else pd.DataFrame(columns=["run", "status", "reason"])
    for column in COLUMNS:
        table[column] = table[column].astype(float) if column in table else np.nan
    return table[["run", "status", "reason", *COLUMNS]].sort_values("run").reset_index(drop=True)


def _given_features(record: dict) -> bool:
    """Whether a simulations row carries its run's features instead of a trace (an external code that
    extracts its own, an archive of features: `shockcal.simulators`)."""
    return all(column in record for column in COLUMNS) and len(record["t_us"]) == 0


def _trace_column(record: dict, column: str, source) -> np.ndarray:
    """A run's trace column (`t_us` or `v_m_s`) as floats; text (a chunk saved as CSV) or a trace of
    another length than its partner is an InputError naming the run."""
    value = record[column]
    if isinstance(value, str) or np.ndim(value) != 1:
        raise InputError(f"{source}: run {record['run']}: {column} is {type(value).__name__}, not a list of numbers "
                         "(simulation tables are Parquet, as `shockcal simulate` writes them)")
    try:
        values = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{source}: run {record['run']}: {column} holds values that are not numbers") from None
    if len(values) != len(np.asarray(record["t_us"] if column == "v_m_s" else record["v_m_s"])):
        raise InputError(f"{source}: run {record['run']}: t_us and v_m_s differ in length")
    return values


def readout_sd(values) -> float:
    """The read-out sd (m/s) of a feature's replicates: 1.4826 x their median absolute deviation
    (scipy), the sd of the body of their distribution. A replicate whose mixture splits another way
    (105S: 1 in 20 reads v_elastic 30 m/s low) would otherwise set it; the record's own read is one
    of the body, not of the rare split."""
    return float(stats.median_abs_deviation(np.asarray(values, dtype=float), scale="normal"))


def record_features(path, settings: ExtractorSettings, shot: str, time_column=None, velocity_column=None,
                    replicates: int = 0, seed: int = 0) -> dict:
    """The ten features of a measured record (`shockcal.velocimetry.records.read_record`) of `shot`; an InputError
    naming the record and the shot when it has none.

    With `replicates` > 0, also each calibration feature's read-out sd on the record
    (`readout_sd_<feature>`, m/s: the sd over that many replicates of the record's noise, seeded by
    `seed`; `readout_replicates`) and the noise model it came from (`noise_sd_m_s`, `noise_ar_order`,
    `readout_half_window_ns`); with 0, only the read-out window and the noise sd, and read-out sds of 0.
    """
    from shockcal.velocimetry.records import read_record

    t, v = read_record(path, _column(time_column), _column(velocity_column))
    try:
        extraction = extract(t, v, settings)
        copies = readout_replicates(t, v, settings, replicates, seed) if replicates else None
    except FeatureError as exc:
        raise InputError(f"record {path}: no features for shot {shot}: {exc}") from exc
    noise = extraction.noise
    row = dict(extraction.features)
    for column in CALIBRATION_FEATURES:
        row[f"readout_sd_{column}"] = 0.0 if copies is None else readout_sd(copies[column])
    row.update(noise_sd_m_s=np.nan if noise is None else noise.sd_m_s,
               noise_ar_order=0 if noise is None else len(noise.ar),
               readout_half_window_ns=0.0 if noise is None else 1e3 * noise.half_window_us)
    return row


def _column(value):
    return int(value) if isinstance(value, str) and value.isdigit() else value


def check_failures(table, max_fraction: float, shot: str, allow_empty: bool = False) -> None:
    """Log the excluded count and their reasons; stop in one line naming the shot, the count and the commonest
    reason (`reason_kind`) when more than `max_fraction` of the runs failed, or when there are no runs (unless
    `allow_empty`: a sequential study's stopped wave; or no `status` column: not a features table)."""
    from shockcal.io import require_columns

    require_columns(table, ["run", "status", "reason"], f"features of shot {shot}")
    if table.empty and allow_empty:
        log.info("shot %s: no runs (a stopped wave)", shot)
        return
    if table.empty:
        raise InputError(f"features of shot {shot}: no runs (a features table with no rows)")
    failed = table[table["status"] != "ok"]
    if failed.empty:
        log.info("shot %s: all %d runs have features", shot, len(table))
        return
    kind_of_run = failed["reason"].astype(str).map(reason_kind)
    kinds = kind_of_run.value_counts()
    log.warning("shot %s: %d of %d runs failed and are excluded downstream; by reason: %s", shot, len(failed),
                len(table), "; ".join(f"{kind} ({count})" for kind, count in kinds.items()))
    for r in failed.head(10).itertuples():
        log.warning("  run %s: %s", r.run, r.reason)
    if len(failed) > max_fraction * len(table):
        commonest = kinds.index[0]
        example = failed[kind_of_run == commonest].iloc[0]
        raise ShockcalError(f"shot {shot}: {len(failed)} of {len(table)} runs failed, more than the allowed "
                            f"{max_fraction:.0%} (simulate.max_failed_fraction); the commonest reason, "
                            f"{kinds.iloc[0]} runs: {commonest} (e.g. run {example['run']}: {example['reason']})")


def reason_kind(reason: str) -> str:
    """What a failed run's reason says without its particulars: the text before its first ':', numbers as #
    ("nonzero exit", "output truncated", "negative cell volume in cell # (target) at t = # us after # steps");
    a missing reason (NaN in a table read back) is "(no reason given)"."""
    if not isinstance(reason, str):
        return "(no reason given)"
    return re.sub(r"[-+]?\d+(\.\d*)?([eE][-+]?\d+)?", "#", reason.split(":")[0].strip()) or "(no reason given)"
