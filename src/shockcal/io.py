"""Tables on disk: Parquet (pyarrow) for everything shockcal writes, CSV accepted wherever a table is read.

Each table shockcal writes carries a JSON document under the Parquet schema-metadata key
``shockcal`` (units of its columns, the producing command, and under ``provenance`` the shockcal
version and git commit that wrote it: `shockcal.provenance`): read it with `read_table_metadata`.
Writes go to a temporary file renamed into place, so an interrupted job never leaves a half-written
table that a rerun would mistake for a finished one.
"""

from __future__ import annotations

import contextlib
import json
import os
from pathlib import Path

import numpy as np
import pandas as pd

from shockcal.errors import InputError

METADATA_KEY = b"shockcal"
PARQUET_SUFFIXES = {".parquet", ".pq"}
CSV_SUFFIXES = {".csv"}


def read_table(path: str | Path) -> pd.DataFrame:
    """Read a Parquet or CSV table; the error names the file when it is missing or unreadable."""
    path = Path(path)
    if not path.is_file():
        raise InputError(f"table {path} does not exist")
    suffix = path.suffix.lower()
    try:
        if suffix in PARQUET_SUFFIXES:
            return pd.read_parquet(path)
        if suffix in CSV_SUFFIXES:
            return pd.read_csv(path, encoding=text_encoding(path))
    except Exception as exc:  # pyarrow and pandas raise many types; all mean "unreadable"
        hint = (" (truncated or corrupted? if shockcal wrote it, delete it and rerun: snakemake recomputes only"
                " the missing files)") if suffix in PARQUET_SUFFIXES else ""
        reason = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise InputError(f"table {path} could not be read: {reason}{hint}") from None
    raise InputError(f"table {path}: unknown format '{suffix}' (expected .parquet, .pq or .csv)")


def text_encoding(path: str | Path) -> str:
    """The encoding of a text file from its byte-order mark: UTF-16 (either byte order), UTF-8 with
    a BOM (the mark is dropped), else UTF-8."""
    with open(path, "rb") as handle:
        head = handle.read(4)
    if head.startswith((b"\xff\xfe", b"\xfe\xff")):
        return "utf-16"
    return "utf-8-sig"


def integer_ids(table: pd.DataFrame, column: str, source) -> pd.DataFrame:
    """`table` with its id column `column` (e.g. `run`) as int64; ids written as 1.0 are whole numbers
    and read as 1. A blank, non-numeric or fractional id (1.5) is an InputError naming `source`, the
    row (0-based, as a table reader counts them) and the value."""
    raw = table[column]
    values = pd.to_numeric(raw, errors="coerce")
    numbers = values.to_numpy(dtype=float)
    bad = ~np.isfinite(numbers) | (numbers != np.round(numbers))
    if bad.any():
        row = int(np.argmax(bad))
        value = raw.iloc[row]
        shown = repr(value) if isinstance(value, str) else f"{value}"
        what = "is blank" if pd.isna(value) or str(value).strip() == "" else f"= {shown} is not a whole number"
        raise InputError(f"{source}: row {row}: {column} {what}; {column} ids are integers")
    out = table.copy()
    out[column] = numbers.astype(np.int64)
    return out


def check_unique(table: pd.DataFrame, column: str, source, what: str = "id") -> None:
    """An InputError naming `source` and the rows when a value of `column` appears more than once."""
    repeated = table[column].duplicated(keep=False).to_numpy()
    if repeated.any():
        value = table[column].to_numpy()[repeated][0]
        rows = np.flatnonzero(table[column].to_numpy() == value).tolist()
        raise InputError(f"{source}: {column} {value} appears more than once (rows {rows[:5]}); one row per {what}")


def read_tables(paths, keys: list[str], what: str) -> pd.DataFrame:
    """Tables holding parts of one table (a shot's chunks, a check's batches) as one, stably sorted by
    the first key column; rows repeating `keys` (in one part or across parts) are an InputError naming
    the files, and so are a key column missing and (`run`, `trial`) ids that are not whole numbers."""
    parts = []
    for path in paths:
        part = read_table(path)
        require_columns(part, keys, path)
        parts.append(integer_ids(part, keys[0], path) if keys[0] in ("run", "trial") else part)
    table = pd.concat(parts, ignore_index=True)
    repeated = table.duplicated(keys, keep=False)
    if repeated.any():
        value = table.loc[repeated, keys[0]].iloc[0]
        holders = [str(path) for path, part in zip(paths, parts) if (part[keys[0]] == value).any()]
        if len(holders) == 1:
            raise InputError(f"{holders[0]}: {keys[0]} {value} appears more than once in this {what} table")
        raise InputError(f"{keys[0]} {value} is in more than one {what} table: {', '.join(holders)}")
    return table.sort_values(keys[0], kind="stable").reset_index(drop=True)


def write_table(df: pd.DataFrame, path: str | Path, metadata: dict | None = None) -> Path:
    """Write `df` as Parquet atomically, with `metadata` (JSON-serialisable) in the schema and this
    process's `provenance()` under its key ``provenance`` (the same for every run of one checkout)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    from shockcal.provenance import provenance

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    table = pa.Table.from_pandas(df, preserve_index=False)
    merged = dict(table.schema.metadata or {})
    merged[METADATA_KEY] = json.dumps({**(metadata or {}), "provenance": provenance()}, sort_keys=True).encode()
    table = table.replace_schema_metadata(merged)
    with atomic_path(path) as tmp:
        pq.write_table(table, tmp)
    return path


@contextlib.contextmanager
def atomic_path(path: str | Path):
    """A temporary sibling of `path` (same suffix) to write to: renamed onto `path` when the block
    ends, removed when it fails (a full or read-only disk, an interrupt), so `path` is either the
    finished file or absent. Temporaries left by a killed writer (kill -9) are removed first."""
    path = Path(path)
    for stale in path.parent.glob(f".{path.name}.tmp-*"):
        stale.unlink(missing_ok=True)
    tmp = path.with_name(f".{path.name}.tmp-{os.getpid()}{path.suffix}")
    try:
        yield tmp
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            tmp.unlink(missing_ok=True)
        raise


def read_table_metadata(path: str | Path) -> dict:
    """The shockcal metadata of a Parquet table written by `write_table` ({} for CSV or none)."""
    import pyarrow.parquet as pq

    path = Path(path)
    if path.suffix.lower() not in PARQUET_SUFFIXES:
        return {}
    raw = (pq.read_schema(path).metadata or {}).get(METADATA_KEY)
    return json.loads(raw) if raw else {}


def require_columns(df: pd.DataFrame, columns, source: str | Path) -> None:
    """Raise InputError naming `source` and every missing column."""
    missing = [c for c in columns if c not in df.columns]
    if missing:
        raise InputError(f"{source}: missing column(s) {missing}; found {list(df.columns)}")
