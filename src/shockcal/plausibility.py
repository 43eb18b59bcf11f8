"""Plausibility of units and ranges: a value in the wrong unit stops with a message, not a wrong answer.

A design point outside the prior box (shockcal.design), a VISAR record (shockcal.records) or observed
features (config values, the table calibration reads) whose magnitudes fit another unit better than
the one shockcal reads them in: each check names the file, key or row, what looks wrong, the unit
the value would fit, and the opt-out that says it is intended (docs/workflow.md, "Bad input and
what you get").
"""

from __future__ import annotations

import logging

import numpy as np

from shockcal.errors import InputError

log = logging.getLogger("shockcal.plausibility")

# Plate-impact VISAR records (m/s, microseconds). A record as short as 10 ns still reads (the
# extractor then says whether it holds a rise); seconds or milliseconds fail the time-step range.
PEAK_VELOCITY_M_S = (10.0, 5000.0)
RECORD_DURATION_US = (0.01, 100.0)
TIME_STEP_US = (1e-5, 0.1)          # 0.01 to 100 ns

# Per unit shockcal reads: units a value is often given in by mistake, and the size of one of them
# in the unit read (1 km/s = 1000 m/s; 1 m/s = 1e-4 cm/us; 1 GPa = 0.01 Mbar).
OTHER_UNITS = {
    "m/s": {"km/s": 1e3, "cm/us": 1e4, "cm/s": 1e-2},
    "us": {"ns": 1e-3, "ms": 1e3, "s": 1e6},
    "cm/us": {"m/s": 1e-4, "km/s": 0.1},
    "Mbar": {"GPa": 1e-2, "kbar": 1e-3, "MPa": 1e-5},
}

OBSERVED_OPT_OUT = "checks.observed_units: false"


def range_problem(what: str, value: float, unit: str, bounds, label: str = "the plausible range") -> str | None:
    """None when `value` lies in `bounds`; else what is wrong and, if one fits, the unit it looks to be in."""
    lo, hi = bounds
    if lo <= value <= hi:
        return None
    shown = "" if unit == "-" else f" {unit}"
    text = f"{what} = {value:.6g}{shown} is outside {label} [{lo:g}, {hi:g}]{shown}"
    for other, size in OTHER_UNITS.get(unit, {}).items():
        if lo <= value * size <= hi:
            return f"{text}; it fits if it is in {other} ({value:.6g} {other} = {value * size:.6g} {unit}): give it in {unit}"
    return text


def feature_problems(features) -> list[str]:
    """What looks wrong with one shot's features (`v_*` m/s, `t_*` us): the largest velocity outside
    PEAK_VELOCITY_M_S, or feature times spread over more than a record lasts."""
    velocities = np.array([float(v) for k, v in features.items() if k.startswith("v_")], dtype=float)
    times = np.array([float(v) for k, v in features.items() if k.startswith("t_")], dtype=float)
    problems = []
    if np.isfinite(velocities).any():
        problems.append(range_problem("the largest velocity feature", np.nanmax(velocities), "m/s", PEAK_VELOCITY_M_S))
    if np.isfinite(times).sum() >= 2:
        problems.append(range_problem("the spread of the feature times", np.nanmax(times) - np.nanmin(times), "us",
                                      (0.0, RECORD_DURATION_US[1])))
    return [p for p in problems if p]


def check_observed(features, where: str, enabled: bool, error=InputError) -> None:
    """Raise `error` naming `where` when `features` look like the wrong units (warn instead when not `enabled`)."""
    problems = feature_problems(features)
    if not problems:
        return
    message = f"{where}: {'; '.join(problems)}"
    if enabled:
        raise error(f"{message}. Observed features are velocities in m/s and times in us; "
                    f"if these values are intended, set {OBSERVED_OPT_OUT}")
    log.warning("%s (accepted: %s)", message, OBSERVED_OPT_OUT)


def check_observed_table(table, shots, source: str, enabled: bool) -> None:
    """`check_observed` on the row of each of `shots` in an observed-features table (shot + feature columns)."""
    for shot in shots:
        rows = table[table["shot"].astype(str) == shot]
        check_observed(rows.iloc[0].to_dict(), f"{source}: shot {shot}", enabled)
