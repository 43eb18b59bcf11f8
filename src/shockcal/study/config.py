"""Accessors of a validated study config: a shot's section, the inputs and their box, the end time."""

from __future__ import annotations

import math

from shockcal.design.settings import WaveSettings
from shockcal.errors import ConfigError
from shockcal.units import MM_TO_CM, VELOCITY_TO_M_S, user_columns, user_units

AUTO_END_MARGIN_US = 0.1   # `hydro.end_time_us: auto` and `per_run`: simulated time beyond the end of the analysis window
# `per_run`: a run ends after its free surface passes this share of its impact velocity: the extractor's arrival
# threshold on a trace at rest (velocimetry.features.QUIET_ARRIVAL_FRACTION, 0.002 of the rise) times 1.5, a bound
# of the rise over the impact velocity (the plateau lies within 0.85-1.05 of it), so the arrival comes no later
PER_RUN_RISE_FRACTION = 0.003


def shot_config(config: dict, shot: str) -> dict:
    """The config block of one shot, or a ConfigError listing the known shots."""
    try:
        return config["shots"][shot]
    except KeyError:
        raise ConfigError(f"unknown shot '{shot}'; the config defines {sorted(config['shots'])}") from None


def end_time_us(config: dict, shot: dict) -> float:
    """Simulated time of a run of `shot` (us): `hydro.end_time_us`, or with `auto` (and at most, with
    `per_run`) the latest time the feature extractor can need. The free surface starts to move no later than target / c0 after
    impact (the elastic precursor travels faster than the bulk sound speed c0 = sqrt(c1 / rho0));
    the analysis window ends `window_after_arrival_us` later; AUTO_END_MARGIN_US is added. A run whose
    window still reaches past its end fails in the extractor with a reason, never silently."""
    requested = config["hydro"]["end_time_us"]
    if requested not in ("auto", "per_run"):
        return float(requested)
    return analysis_end_us(config, shot) + AUTO_END_MARGIN_US


def analysis_end_us(config: dict, shot: dict) -> float:
    """The latest time after impact (us) the analysis window of `shot` (a shot's config section) can
    end: target / c0 (the free surface starts to move no later) plus `window_after_arrival_us`."""
    material = config["material"]
    c0_cm_us = math.sqrt(material["eos"]["c1_Mbar"] / material["rho0_g_cc"])
    return shot["target_mm"] * MM_TO_CM / c0_cm_us + shot["analysis"]["window_after_arrival_us"]


def input_names(config: dict) -> list[str]:
    """All calibration inputs in config order (the design table's columns)."""
    return list(config["inputs"])


def prior_bounds(config: dict) -> dict[str, tuple[float, float]]:
    """The prior box, input by input in config order: name -> (min, max) in the box's native units."""
    return {name: (box["min"], box["max"]) for name, box in config["inputs"].items()}


def input_user_units(config: dict) -> dict[str, str]:
    """Each input's unit for a user (`shockcal.units.user_unit` of its declared `unit`): a shear-modulus
    input (a shot's `shear_modulus_inputs`) in Mbar reads in GPa, another pressure (a stress) in MPa, a
    velocity in m/s; MPa, GPa, m/s and dimensionless inputs as declared."""
    moduli = {name for shot in config["shots"].values() for name in shot["shear_modulus_inputs"]}
    return user_units({name: box["unit"] for name, box in config["inputs"].items()}, moduli)


def input_columns(config: dict) -> dict[str, tuple[str, str, float]]:
    """Each input -> (its name for a user, e.g. A_MPa; its user unit; the factor from its declared unit):
    `shockcal.units.user_columns` with `input_user_units`."""
    return user_columns({name: box["unit"] for name, box in config["inputs"].items()}, input_user_units(config))


def user_box_widths(config: dict) -> dict[str, float]:
    """Each input's box width in its user unit, keyed by its name for a user (A_MPa, V1_m_s: the names of
    the posterior summaries)."""
    columns = input_columns(config)
    return {columns[name][0]: (high - low) * columns[name][2] for name, (low, high) in prior_bounds(config).items()}


def run_cost_mm_us(config: dict, shot: str, run_set: str = "training") -> float:
    """One hydrocode run of `shot`'s cost up to a factor common to the study's shots, to start the longest
    jobs first: its cells (the plates' total thickness, mm) times its simulated time (us; the predictive
    runs' `predict.end_time_us`, others `end_time_us`). The time step is set by the cell size and the sound
    speed, alike for every shot of one material."""
    shot_section = shot_config(config, shot)
    end = config["predict"]["end_time_us"] if run_set == "predict" else end_time_us(config, shot_section)
    return (shot_section["flyer_mm"] + shot_section["target_mm"]) * end


def velocity_box_m_s(config: dict, shot: str) -> tuple[float, float] | None:
    """The impact-velocity box of `shot` in m/s (its `velocity_input`'s box, converted from the input's
    unit), or None when that unit is not a velocity unit shockcal knows (`VELOCITY_TO_M_S`)."""
    box = config["inputs"][shot_config(config, shot)["velocity_input"]]
    factor = VELOCITY_TO_M_S.get(str(box["unit"]).strip())
    return None if factor is None else (box["min"] * factor, box["max"] * factor)


SHEAR_MODULUS_TO_MBAR = {"Mbar": 1.0, "GPa": 0.01, "kbar": 1e-3}


def shear_modulus_box_Mbar(config: dict, shot: str) -> tuple[float, float] | None:
    """The smallest and largest shear modulus of `shot`'s prior box (Mbar, the sum of its
    `shear_modulus_inputs`' bounds; for a strength law with its own G law, which reads no shot moduli,
    its G0_GPa box: G's rise with pressure left out), or None when one of them is in a unit not in
    SHEAR_MODULUS_TO_MBAR."""
    names = list(shot_config(config, shot)["shear_modulus_inputs"])
    if not all(name in config["inputs"] for name in names) and "G0_GPa" in config["inputs"]:
        names = ["G0_GPa"]
    units = [str(config["inputs"][name]["unit"]).strip() for name in names]
    if any(unit not in SHEAR_MODULUS_TO_MBAR for unit in units):
        return None
    return tuple(sum(config["inputs"][name][end] * SHEAR_MODULUS_TO_MBAR[unit]
                     for name, unit in zip(names, units)) for end in ("min", "max"))


def shear_modulus_increment_box_Mbar(config: dict, name: str) -> tuple[float, float] | None:
    """The range (Mbar) of next-shot candidate `name`'s shear modulus over its reference shot's,
    G_ref s (T0 - T_ref), for G_ref in the reference shot's box (`shear_modulus_box_Mbar`) and s in
    next_shot.shear_modulus_log_slope_per_K: (0, 0) at the reference temperature; None when the
    reference shot's box is in a unit shockcal cannot convert."""
    spec = config["next_shot"]["candidates"][name]
    box = shear_modulus_box_Mbar(config, spec["shot"])
    if box is None:
        return None
    temperature = spec.get("initial_temperature_K")
    heating = 0.0 if temperature is None else temperature - config["material"]["T_ref_K"]
    slopes = config["next_shot"]["shear_modulus_log_slope_per_K"]
    ends = [g * slopes[end] * heating for g in box for end in ("min", "max")]
    return min(ends), max(ends)


def plateau_us(config: dict, flyer_mm: float, target_mm: float, shear_modulus_Mbar: float) -> float:
    """Time from the first arrival to the release's arrival at the free surface (us) of a symmetric
    impact of the config's material (`shockcal.plausibility.release_times_us`)."""
    from shockcal.plausibility import release_times_us

    material = config["material"]
    arrival, release = release_times_us(flyer_mm, target_mm, material["rho0_g_cc"], material["eos"]["c1_Mbar"],
                                        shear_modulus_Mbar)
    return release - arrival


def candidate_config(config: dict, name: str) -> dict:
    """A next-shot candidate (`next_shot.candidates.<name>`) as a shot section: flyer_mm, target_mm,
    initial_temperature_K, velocity_m_s, its reference `shot`, that shot's `shear_modulus_inputs`, and
    `analysis`: the reference shot's cut-off, and its window unless the candidate gives one, scaled
    by the ratio of the two plateaus (`plateau_us` at the reference shot's largest shear modulus, the
    earliest release): the same share of the plateau as the reference shot's window. An unknown
    candidate is a ConfigError listing the known ones."""
    candidates = config["next_shot"]["candidates"]
    if name not in candidates:
        raise ConfigError(f"unknown next-shot candidate '{name}'; the config defines {sorted(candidates)}")
    spec = candidates[name]
    reference = shot_config(config, spec["shot"])
    analysis = dict(reference["analysis"])
    if spec.get("window_after_arrival_us") is not None:
        analysis["window_after_arrival_us"] = float(spec["window_after_arrival_us"])
    else:
        box = shear_modulus_box_Mbar(config, spec["shot"])
        if box is not None:
            share = (plateau_us(config, spec["flyer_mm"], spec["target_mm"], box[1])
                     / plateau_us(config, reference["flyer_mm"], reference["target_mm"], box[1]))
            analysis["window_after_arrival_us"] = analysis["window_after_arrival_us"] * share
    return {"flyer_mm": spec["flyer_mm"], "target_mm": spec["target_mm"], "velocity_m_s": spec["velocity_m_s"],
            "initial_temperature_K": spec.get("initial_temperature_K"), "shot": spec["shot"],
            "shear_modulus_inputs": list(reference["shear_modulus_inputs"]), "analysis": analysis}


def wave_sizes(config: dict) -> list[int]:
    """Runs per shot of each wave of a sequential study (`WaveSettings.sizes`); [design.n_runs] for the paper's
    design (`design.strategy: lhs`)."""
    design = config["design"]
    return WaveSettings.from_section(design["waves"]).sizes() if design["strategy"] == "waves" \
        else [design["n_runs"]]
