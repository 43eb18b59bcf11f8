"""Reading measured velocity records (time in microseconds, velocity in m/s).

`read_record` takes the paper's released VISAR files as they are ('%' comment lines, the last of
which names the columns, e.g. "% Up (m/s)  t (us)" or "% time (us)  Up (m/s)": the order differs
between files) and general CSV or whitespace tables whose time and velocity columns the user names.
The record is returned as released: noise, baseline offset and pre-trigger content are handled by
the feature extractor (shockcal.features), not here.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pandas as pd

from shockcal.errors import InputError

MIN_POINTS = 50
_TIME_NAMES = re.compile(r"^(t|time|t_us)\b", re.IGNORECASE)
_VELOCITY_NAMES = re.compile(r"^(up|u|v|vel|velocity|ufs|u_fs|v_m_s)\b", re.IGNORECASE)


def read_record(path, time_column=None, velocity_column=None) -> tuple[np.ndarray, np.ndarray]:
    """(t_us, v_m_s) of a record; columns named by the user (name or 0-based index) or detected."""
    path = Path(path)
    if not path.is_file():
        raise InputError(f"record {path} does not exist")
    table = _read_table(path)
    t_col = _pick(table, time_column, _TIME_NAMES, path, "time")
    v_col = _pick(table, velocity_column, _VELOCITY_NAMES, path, "velocity")
    t = pd.to_numeric(table[t_col], errors="coerce").to_numpy(dtype=float)
    v = pd.to_numeric(table[v_col], errors="coerce").to_numpy(dtype=float)
    check_record(t, v, path)
    return t, v


def check_record(t: np.ndarray, v: np.ndarray, source) -> None:
    """Enough finite points and strictly increasing time, else an error naming `source`."""
    if len(t) < MIN_POINTS:
        raise InputError(f"record {source}: {len(t)} points; at least {MIN_POINTS} are needed")
    bad = ~(np.isfinite(t) & np.isfinite(v))
    if bad.any():
        raise InputError(f"record {source}: {int(bad.sum())} non-numeric or NaN values (first at row {int(np.argmax(bad))})")
    steps = np.diff(t)
    if np.any(steps <= 0):
        raise InputError(f"record {source}: time is not increasing at row {int(np.argmax(steps <= 0)) + 1}")


def _read_table(path: Path) -> pd.DataFrame:
    """A table with named columns: from a '%' header line, or a CSV/whitespace header."""
    lines = path.read_text(errors="replace").splitlines()
    comments = [line.lstrip("%").strip() for line in lines if line.startswith("%")]
    body = [line for line in lines if line.strip() and not line.startswith("%")]
    if not body:
        raise InputError(f"record {path}: no data lines")
    sep = "," if "," in body[0] else r"\s+"
    first = re.split(sep, body[0].strip())
    has_header = not all(_is_number(x) for x in first)
    data = pd.read_csv(pd.io.common.StringIO("\n".join(body)), sep=sep, header=0 if has_header else None,
                       engine="python")
    if not has_header and comments:
        names = [n.strip() for n in re.split(r"\s{2,}|\t", comments[-1]) if n.strip()]
        if len(names) == data.shape[1]:
            data.columns = names
    return data


def _is_number(text: str) -> bool:
    try:
        float(text)
        return True
    except ValueError:
        return False


def _pick(table: pd.DataFrame, wanted, pattern, path, role: str):
    """The column the user named (name or index), or the one whose name matches `pattern`."""
    columns = list(table.columns)
    if wanted is not None:
        if isinstance(wanted, int) and 0 <= wanted < len(columns):
            return columns[wanted]
        if wanted in columns:
            return wanted
        raise InputError(f"record {path}: no {role} column {wanted!r}; columns are {columns}")
    matches = [c for c in columns if pattern.match(str(c).strip())]
    if len(matches) != 1:
        raise InputError(f"record {path}: cannot tell which column is {role} among {columns}; "
                         f"name it (observed.records.<shot>.{role}_column)")
    return matches[0]
