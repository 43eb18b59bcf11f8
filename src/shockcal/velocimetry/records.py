"""Reading measured velocity records (time in microseconds, velocity in m/s).

`read_record` takes the paper's released VISAR files as they are ('%' comment lines, the last of
which names the columns, e.g. "% Up (m/s)  t (us)" or "% time (us)  Up (m/s)": the order differs
between files) and general CSV or whitespace tables whose time and velocity columns the user names.
The record is returned as released: noise, baseline offset and pre-trigger content are handled by
the feature extractor (shockcal.velocimetry.features), not here. A record whose peak velocity, duration or time
step is implausible for a plate-impact VISAR record in m/s and microseconds (shockcal.plausibility:
km/s, ns, ...) is an error unless the environment sets SHOCKCAL_ALLOW_IMPLAUSIBLE_RECORDS=1.
"""

from __future__ import annotations

import logging
import os
import re
from pathlib import Path

import numpy as np
import pandas as pd

from shockcal.errors import InputError
from shockcal.plausibility import PEAK_VELOCITY_M_S, RECORD_DURATION_US, TIME_STEP_US, range_problem

log = logging.getLogger("shockcal.velocimetry.records")
MIN_POINTS = 50
# A velocity that rises by no more than this many times its noise holds no shock. The paper's three records
# rise 964-3071 times their noise (the same in km/s); cut before their shock (at 0.25-1.25 us) 13-41 times.
NO_SHOCK_RISE_TO_NOISE = 100.0
OPT_OUT = "SHOCKCAL_ALLOW_IMPLAUSIBLE_RECORDS"
_TIME_NAMES = re.compile(r"^(t|time|t_us)\b", re.IGNORECASE)
_VELOCITY_NAMES = re.compile(r"^(up|u|v|vel|velocity|ufs|u_fs|v_m_s)\b", re.IGNORECASE)
_DECIMAL_COMMA = re.compile(r"^[-+]?\d*,\d+([eE][-+]?\d+)?$")


def read_record(path, time_column=None, velocity_column=None) -> tuple[np.ndarray, np.ndarray]:
    """(t_us, v_m_s) of a record; columns named by the user (name or 0-based index) or detected."""
    path = Path(path)
    if not path.is_file():
        raise InputError(f"record {path} does not exist")
    table = _read_table(path)
    if table.shape[1] < 2:
        raise InputError(f"record {path}: one column ({table.columns[0]!r}); a record needs two, time (us) and "
                         "velocity (m/s)")
    t_col = _pick(table, time_column, _TIME_NAMES, path, "time")
    v_col = _pick(table, velocity_column, _VELOCITY_NAMES, path, "velocity")
    t = pd.to_numeric(table[t_col], errors="coerce").to_numpy(dtype=float)
    v = pd.to_numeric(table[v_col], errors="coerce").to_numpy(dtype=float)
    check_record(t, v, path)
    check_plausible(t, v, path)
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


def check_plausible(t: np.ndarray, v: np.ndarray, source) -> None:
    """Peak velocity, duration and median time step in the plausible ranges of shockcal.plausibility, else
    an error saying which unit would fit (a warning under OPT_OUT=1); a record that holds no shock
    (`check_shock`) is an error."""
    check_shock(t, v, source)
    problems = [
        range_problem("peak velocity", float(np.max(v)), "m/s", PEAK_VELOCITY_M_S) if np.ptp(v) > 0 else None,
        range_problem("duration", float(t[-1] - t[0]), "us", RECORD_DURATION_US),
        range_problem("median time step", float(np.median(np.diff(t))), "us", TIME_STEP_US),
    ]
    problems = [p for p in problems if p]
    if not problems:
        return
    message = f"record {source}: {'; '.join(problems)}"
    if os.environ.get(OPT_OUT) != "1":
        raise InputError(f"{message}. Records are read as time in us and velocity in m/s; "
                         f"if the record is right as it is, set {OPT_OUT}=1 in the environment")
    log.warning("%s (accepted: %s=1)", message, OPT_OUT)


def check_shock(t: np.ndarray, v: np.ndarray, source) -> None:
    """A record whose peak is below PEAK_VELOCITY_M_S and whose velocity rises by less than
    NO_SHOCK_RISE_TO_NOISE times its noise ends before the shock arrives (a record in km/s rises as far
    above its noise as one in m/s, only its peak is low): an error saying so, naming `source`."""
    rise = float(np.ptp(v))
    steps = np.diff(v)
    noise = 1.4826 * float(np.median(np.abs(steps - np.median(steps)))) / np.sqrt(2.0)   # robust sd of v
    if np.max(v) < PEAK_VELOCITY_M_S[0] and rise <= NO_SHOCK_RISE_TO_NOISE * noise:
        how = (f"is {v[0]:.3g} m/s throughout" if rise == 0 else
               f"stays below {PEAK_VELOCITY_M_S[0]:g} m/s, rising {rise:.3g} m/s, {rise / noise:.0f} times its noise "
               f"({noise:.2g} m/s), where a shock rises over {NO_SHOCK_RISE_TO_NOISE:g} times")
        raise InputError(f"record {source}: no shock in it: up to its end at {t[-1]:.4g} us its velocity {how}: the "
                         "record ends before the shock arrives; give the whole record")


def _read_table(path: Path) -> pd.DataFrame:
    """A table with named columns: from a '%' header line, or a header line; fields separated by
    whitespace (tabs), ';' or ','; UTF-8 (with or without a byte-order mark) or UTF-16, any line ends.
    A binary file, rows of unequal width or decimal commas are errors naming the file and the line."""
    raw = path.read_bytes()
    if raw.startswith((b"\xff\xfe", b"\xfe\xff")):       # UTF-16 (a spreadsheet's "Unicode text")
        text = raw.decode("utf-16", errors="replace")
    elif b"\0" in raw:
        raise InputError(f"record {path}: a binary file, not a text table of time and velocity columns")
    else:
        text = raw.decode("utf-8-sig", errors="replace")     # a UTF-8 byte-order mark is dropped
    lines = text.splitlines()
    comments = [line.lstrip("%").strip() for line in lines if line.startswith("%")]
    numbered = [(i + 1, line) for i, line in enumerate(lines) if line.strip() and not line.startswith("%")]
    if not numbered:
        raise InputError(f"record {path}: no data lines")
    first = numbered[0][1]
    sep = next((c for c in ";," if c in first and "\t" not in first), None)
    fields = [line.split(sep) for _, line in numbered]
    odd = next((k for k, row in enumerate(fields) if len(row) != len(fields[0])), None)
    if odd is not None:
        raise InputError(f"record {path}: line {numbered[odd][0]} has {len(fields[odd])} fields, "
                         f"line {numbered[0][0]} has {len(fields[0])}")
    comma_decimal = next((x for x in fields[-1] if _DECIMAL_COMMA.match(x.strip())), None)
    if comma_decimal:
        raise InputError(f"record {path}: line {numbered[-1][0]}: {comma_decimal.strip()!r} has a decimal comma; "
                         f"write numbers with a decimal point")
    body = [line for _, line in numbered]
    has_header = not all(_is_number(x.strip()) for x in fields[0])
    try:
        data = pd.read_csv(pd.io.common.StringIO("\n".join(body)), sep=sep or r"\s+", header=0 if has_header else None,
                           engine="python")
    except (pd.errors.ParserError, ValueError) as exc:
        raise InputError(f"record {path}: not a readable table: {str(exc).splitlines()[0]}") from None
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
