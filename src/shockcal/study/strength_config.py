"""The study's strength law (config `strength`): the prior box it calibrates, checked before any run.

With a `strength.model` whose box is not `inputs` itself (every law but Johnson-Cook, whose
declaration has `code_unit_columns`), `apply_strength_model` rewrites the validated config's
`inputs` into the law's box (`strength.inputs`, else `strength.models_file`), each shot's velocity
input and, for a law without a shear-modulus law, each shot's modulus inputs, so that every stage
reads its box, names and units from `inputs` as for Johnson-Cook; `strength.inputs` then holds the
whole box, so the rewritten config validates to itself (the workflow's jobs read it again).
Johnson-Cook configs are left alone. A law's material constants (PTW's molar mass, density, melt
temperature; Steinberg-Guinan's melt law) come from `material` (`material_constants`), unless boxed.
"""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np

from shockcal.design.settings import InputRange
from shockcal.errors import ConfigError, InputError
from shockcal.hydro.laws import DEFAULT_COLUMNS, DEFAULT_MODEL, Law, flow_stress_at_states, get_law, law_values
from shockcal.hydro.laws.boxes import load_boxes
from shockcal.settings_model import SettingsError

# states at which a box's corners must give a finite, non-negative flow stress:
# (plastic strain, equivalent strain rate 1/s, temperature K, pressure GPa, density ratio)
CORNER_STATES = ((0.0, 1.0e-3, 298.0, 0.0, 1.0), (0.2, 1.0e6, 298.0, 5.0, 1.06), (0.5, 1.0e7, 600.0, 10.0, 1.1))
MAX_CORNERS = 2 ** 16


def section_model(section: dict | None) -> str:
    """The law a config section names (`model` of `strength` or of a reference set): DEFAULT_MODEL when it is
    left out; the one place that says which law that is."""
    return (section or {}).get("model", DEFAULT_MODEL)


def strength_model(config: dict) -> str:
    """The study's law (`strength.model`; johnson-cook when the section is left out)."""
    return section_model(config.get("strength"))


def strength_law(config: dict) -> Law:
    """The study's law's declaration (`shockcal.hydro.laws.get_law`)."""
    return get_law(strength_model(config))


def strength_parameters(config: dict) -> list[str]:
    """The study's strength-law inputs: the law's design columns (`Law.column`) that `inputs` boxes, in the
    law's order (Johnson-Cook's A, B, C, n, m; another law's boxed parameters)."""
    law = strength_law(config)
    return [law.column(p) for p in law.params if law.column(p) in config["inputs"]]


def next_shot_targets(config: dict) -> list[str]:
    """`next_shot.targets`, or every strength parameter of the study's law when it is null (the default)."""
    targets = (config.get("next_shot") or {}).get("targets")
    return strength_parameters(config) if targets is None else list(targets)


def apply_strength_model(config: dict, source: str) -> None:
    """For a law without `code_unit_columns` (all but Johnson-Cook): `inputs` becomes the law's box (declared units) followed by the
    shots' velocity inputs and, for a law without a G law, their shear-modulus inputs; `calibration.cube_power`
    drops Johnson-Cook's inputs the law does not have (a Johnson-Cook config's power, kept by an overlay that
    cannot delete it); a name the law has (Steinberg-Guinan's n) keeps its power. ConfigError naming the key:
    a parameter the law does not have, a missing bound, min >= max, an input that is neither the law's nor a
    shot's, a material constant the law needs and `material` does not give, a box corner whose flow stress is
    negative or not finite."""
    law = strength_law(config)
    if law.code_unit_columns:      # its box is `inputs` itself
        return
    section = config["strength"]
    given = section.get("inputs") or {}
    for name in given:
        if name not in law.names():
            raise ConfigError(f"{source}: strength.inputs.{name}: not a parameter of {law.name} "
                              f"(parameters: {', '.join(law.names())})")
    models_file = section.get("models_file", "config/models.yaml")
    file_box = _file_box(models_file, law.name, source) if any(
        p.calibrated and p.name not in given for p in law.params) else {}
    box = {}
    for param in law.params:
        if param.name in given:
            low, high, where = given[param.name]["min"], given[param.name]["max"], f"strength.inputs.{param.name}"
        elif param.name in file_box:
            low, high, where = file_box[param.name].low, file_box[param.name].high, f"{models_file}: {law.name}.{param.name}"
        elif param.calibrated:
            raise ConfigError(f"{source}: strength.inputs.{param.name}: missing; {law.name} needs a box for it "
                              f"(give min and max, or a low/high in {models_file})")
        else:
            continue
        try:
            box[param.name] = InputRange(min=low, max=high, unit=param.unit).model_dump()
        except SettingsError as exc:
            raise ConfigError(f"{source}: {where}.{exc.field}: {exc.reason}") from None
    check_corners(law, box, material_constants(config, law.name, box, source), source)
    config["inputs"] = {**box, **_shot_inputs(config, law, given, source)}
    section["inputs"] = {name: {"min": b["min"], "max": b["max"]} for name, b in box.items()}   # idempotent
    cube = config["calibration"]["cube_power"]
    config["calibration"]["cube_power"] = {k: v for k, v in cube.items()
                                           if k in config["inputs"] or k not in DEFAULT_COLUMNS}


def material_constants(config: dict, model: str, boxed=(), source: str = "config") -> dict[str, float]:
    """The material constants of law `model` that the study does not calibrate (not in `boxed`), by parameter
    name, from the config's `material` (`shockcal.hydro.laws.law_values`, the one place they are filled); a
    constant the material does not give is a ConfigError naming the material key."""
    law = get_law(model)
    boxed = [name for name in boxed if name in law.names()]
    try:
        filled = law_values(law, dict.fromkeys(boxed, 0.0), config["material"])
    except InputError as exc:
        raise ConfigError(f"{source}: {exc}") from None
    return {p.name: filled[p.name] for p in law.params if p.material is not None and p.name not in boxed}


def _file_box(path: str, law_name: str, source: str) -> dict:
    if not Path(path).is_file():
        raise ConfigError(f"{source}: strength.models_file: {path} does not exist")
    return load_boxes(path).get(law_name, {})


def _shot_inputs(config: dict, law, given: dict, source: str) -> dict:
    """The config's inputs the shots read under `law`: velocities, and modulus terms for a law without a G law;
    Johnson-Cook's five (the paper's) are dropped, and so is a law parameter that `given` (strength.inputs)
    boxes with the same bounds (a config this function wrote, read again by a job); anything else is an
    error naming it."""
    shots = config["shots"].values()
    velocity = {spec["velocity_input"] for spec in shots}
    modulus = {name for spec in shots for name in spec["shear_modulus_inputs"]}
    kept = velocity | (modulus if law.shear_modulus is None else set())
    out = {}
    for name, spec in config["inputs"].items():
        if name in kept:
            out[name] = spec
        elif name in DEFAULT_COLUMNS or name in modulus:
            continue
        elif name in given and (given[name]["min"], given[name]["max"]) == (spec["min"], spec["max"]):
            continue
        elif name in law.names():
            raise ConfigError(f"{source}: inputs.{name}: a {law.name} parameter; give its box as strength.inputs.{name}")
        else:
            raise ConfigError(f"{source}: inputs.{name}: neither a {law.name} parameter nor a shot's velocity"
                              f"{' or shear-modulus' if law.shear_modulus is None else ''} input")
    return out


def check_corners(law, box: dict, constants: dict, source: str) -> None:
    """Every corner of the law's box (parameters outside the box at the material's `constants`, by name, and
    their declared defaults) must meet the law's
    constraints (all linear: SG's Ymax >= Y0, PTW's ordering of s0, sinf, y0, yinf, y1, ...; so the
    whole box meets them), and give a finite, non-negative flow stress at CORNER_STATES: a ConfigError
    naming the corner otherwise."""
    names = list(box)
    if 2 ** len(names) > MAX_CORNERS:
        raise ConfigError(f"{source}: strength.inputs: {len(names)} boxed parameters; at most "
                          f"{MAX_CORNERS.bit_length() - 1} (the box's corners are checked)")
    defaults = {**{p.name: p.default for p in law.params if p.default is not None}, **constants}
    for corner in itertools.product(*((box[n]["min"], box[n]["max"]) for n in names)):
        values = {**defaults, **dict(zip(names, corner))}
        where = ", ".join(f"{n}={v:g}" for n, v in zip(names, corner))
        try:
            stresses = flow_stress_at_states(law, values, CORNER_STATES)
        except InputError as exc:
            raise ConfigError(f"{source}: strength: the box's corner {where} breaks the law ({exc}); the law's "
                              "constraints are linear, so boxes that meet them at every corner meet them inside") from None
        bad = [s for s in stresses if not (np.isfinite(s) and s >= 0.0)]
        if bad:
            raise ConfigError(f"{source}: strength: {law.name}'s flow stress is {bad[0]:g} MPa at the box corner "
                              f"{where}; narrow the box (strength.inputs)")
