"""Plausibility of units and ranges: a value in the wrong unit stops with a message, not a wrong answer.

A design point outside the prior box (shockcal.design.tables), a VISAR record (shockcal.velocimetry.records) or observed
features (config values, the table calibration reads) whose magnitudes fit another unit better than
the one shockcal reads them in, and a plastic plateau that does not fit its shot's impact velocity
(`check_plateau`: the records or features of two shots swapped): each check names the file, key or row, what looks wrong, the unit
the value would fit, and the opt-out that says it is intended (docs/workflow.md, "Bad input and
what you get").
"""

from __future__ import annotations

import logging

import numpy as np

from shockcal.errors import InputError
from shockcal.settings_model import SettingsModel, setting

log = logging.getLogger("shockcal.plausibility")


class ChecksSettings(SettingsModel):
    """Which plausibility checks run: the study config's `checks` section (docs/workflow.md, "Bad input and what
    you get"); set one to false only to say that the values it rejects are intended."""

    design_box: bool = setting(True, "Design points must lie inside the prior box (`inputs`).")
    observed_units: bool = setting(True, "Observed features must look like m/s and microseconds.")
    plateau_vs_velocity: bool = setting(
        True, "A shot's measured plastic plateau (v_plastic) must lie in 0.85-1.05 x its impact-velocity box (in m/s): "
        "a symmetric impact's plateau is about the impact velocity, so one far outside means the records of two shots "
        "are swapped.")
    features_in_training_range: bool = setting(
        True, "Before a calibration, each measured calibration feature (m/s) must lie within its training runs' range, "
        "widened on each side by a quarter of its width (docs/calibration.md, \"Measured features against the "
        "training runs\"): a feature beyond it is one the emulator cannot reproduce (a misread record, another shot's "
        "features, a prior box that misses the material), and its posterior would be the prior box. `shockcal "
        "calibrate` stops in one line naming the shot, the feature, the value and the range; the synthetic-truth "
        "checks' pseudo-measurements are only logged (false: measurements are only logged too).")

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

# The plastic plateau of a symmetric impact (flyer and target of one material) against the impact
# velocity: the free surface moves at about the impact velocity, a little less with strength. Over the
# 120 training runs of the quick study (results/quick, 40 per shot) v_plastic / impact velocity is
# 0.905-0.996 (104S 0.922-0.996, 105S 0.905-0.994, 106S 0.911-0.995); the published measurements lie at
# 0.93-1.05 of their shot's velocity box. A plateau outside [0.85 v_min, 1.05 v_max] of its shot's box is
# another shot's record or features (adjacent shots of the paper differ by 1.3-1.7x).
PLATEAU_RATIO = (0.85, 1.05)
PLATEAU_OPT_OUT = "checks.plateau_vs_velocity: false"


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


def plateau_problem(v_plastic_m_s: float, velocity_box_m_s) -> str | None:
    """None when the plastic plateau (m/s) lies in PLATEAU_RATIO times the shot's impact-velocity box
    (m/s); else what is wrong."""
    lo, hi = velocity_box_m_s
    low, high = PLATEAU_RATIO[0] * lo, PLATEAU_RATIO[1] * hi
    if low <= v_plastic_m_s <= high:
        return None
    return (f"the plastic plateau v_plastic = {v_plastic_m_s:.4g} m/s is outside [{low:.4g}, {high:.4g}] m/s, "
            f"{PLATEAU_RATIO[0]:g}-{PLATEAU_RATIO[1]:g} x the shot's impact velocity box [{lo:.4g}, {hi:.4g}] m/s "
            "(in a symmetric impact the free surface moves at about the impact velocity): another shot's record "
            "or features?")


def check_plateau(features, velocity_box_m_s, where: str, enabled: bool, error=InputError) -> None:
    """Raise `error` naming `where` when `plateau_problem` finds one in a shot's `features` (a mapping
    holding `v_plastic`, m/s; warn instead when not `enabled`). Features whose units look wrong
    (`feature_problems`) are left to `check_observed`, which says so."""
    if feature_problems(features):
        return
    problem = plateau_problem(float(features["v_plastic"]), velocity_box_m_s)
    if problem is None:
        return
    if enabled:
        raise error(f"{where}: {problem}; if it is intended, set {PLATEAU_OPT_OUT}")
    log.warning("%s: %s (accepted: %s)", where, problem, PLATEAU_OPT_OUT)


def release_times_us(flyer_mm: float, target_mm: float, rho0_g_cc: float, c1_Mbar: float, shear_modulus_Mbar: float
                     ) -> tuple[float, float]:
    """(first arrival, release arrival) at the target's free surface, us after impact, of a symmetric
    impact, from 1-D wave paths.

    Speeds: the bulk sound speed c_bulk = sqrt(c1 / rho0) carries the plastic shock (its lower bound);
    the longitudinal elastic speed c_L = sqrt(c_bulk^2 + 4 G / (3 rho0)) carries the elastic precursor and
    the head of a release. The precursor crosses the target first: arrival = target / c_L. The plastic
    shock crosses the flyer and reflects from its back as a release, whose head crosses the flyer and
    the target: release = flyer / c_bulk + (flyer + target) / c_L, so the plateau lasts
    flyer / c_bulk + flyer / c_L after the arrival. (The precursor's own reflection, 2 flyer / c_L after
    the arrival, carries only the precursor's amplitude.) The hydrocode's plateau of the paper's shots
    falls 3% at 1.12-1.22 us after the arrival, 0.07-0.13 us before this estimate (the shock is faster
    than c_bulk and a release faster in compressed metal): a window reaching the estimate surely holds
    the release."""
    c_bulk = (c1_Mbar / rho0_g_cc) ** 0.5                                     # cm/us
    c_l = (c_bulk**2 + 4.0 * shear_modulus_Mbar / (3.0 * rho0_g_cc)) ** 0.5    # cm/us
    flyer, target = flyer_mm * 0.1, target_mm * 0.1                            # cm
    return target / c_l, flyer / c_bulk + (flyer + target) / c_l


BOX_SLACK = 1e-9   # share of a box's width allowed outside it: the float noise of a value written at a bound


def outside_box(values, low: float, high: float) -> np.ndarray:
    """Mask of `values` outside [low, high] beyond the float noise of a value written at a bound and
    read back (BOX_SLACK of the box's width)."""
    slack = BOX_SLACK * (high - low)
    values = np.asarray(values, dtype=float)
    return (values < low - slack) | (values > high + slack)
