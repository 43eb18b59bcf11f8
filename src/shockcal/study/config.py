"""Accessors of a validated study config: a shot's section, the inputs and their box, the end time."""

from __future__ import annotations

import math

from shockcal.errors import ConfigError
from shockcal.units import MM_TO_CM, VELOCITY_TO_M_S

AUTO_END_MARGIN_US = 0.1   # `hydro.end_time_us: auto`: simulated time beyond the latest end of the analysis window


def shot_config(config: dict, shot: str) -> dict:
    """The config block of one shot, or a ConfigError listing the known shots."""
    try:
        return config["shots"][shot]
    except KeyError:
        raise ConfigError(f"unknown shot '{shot}'; the config defines {sorted(config['shots'])}") from None


def end_time_us(config: dict, shot: dict) -> float:
    """Simulated time of a run of `shot` (us): `hydro.end_time_us`, or with `auto` the latest time
    the feature extractor can need. The free surface starts to move no later than target / c0 after
    impact (the elastic precursor travels faster than the bulk sound speed c0 = sqrt(c1 / rho0));
    the analysis window ends `window_after_arrival_us` later; AUTO_END_MARGIN_US is added. A run whose
    window still reaches past its end fails in the extractor with a reason, never silently."""
    requested = config["hydro"]["end_time_us"]
    if requested != "auto":
        return float(requested)
    material = config["material"]
    c0_cm_us = math.sqrt(material["eos"]["c1_Mbar"] / material["rho0_g_cc"])
    window = shot["analysis"]["window_after_arrival_us"]
    return shot["target_mm"] * MM_TO_CM / c0_cm_us + window + AUTO_END_MARGIN_US


def input_names(config: dict) -> list[str]:
    """All calibration inputs in config order (the design table's columns)."""
    return list(config["inputs"])


def prior_bounds(config: dict) -> dict[str, tuple[float, float]]:
    """The prior box, input by input in config order: name -> (min, max) in the box's native units."""
    return {name: (box["min"], box["max"]) for name, box in config["inputs"].items()}


def velocity_box_m_s(config: dict, shot: str) -> tuple[float, float] | None:
    """The impact-velocity box of `shot` in m/s (its `velocity_input`'s box, converted from the input's
    unit), or None when that unit is not a velocity unit shockcal knows (`VELOCITY_TO_M_S`)."""
    box = config["inputs"][shot_config(config, shot)["velocity_input"]]
    factor = VELOCITY_TO_M_S.get(str(box["unit"]).strip())
    return None if factor is None else (box["min"] * factor, box["max"] * factor)
