"""Published parameter sets a study compares its posterior with (config `study.reference_sets`).

A set names its law (`model`) and gives values by that law's parameter names, in the unit each name
carries (`A_MPa`, `B_MPa`, `C`, `n`, `m` for Johnson-Cook; src/shockcal/hydro/laws/declarations.py). The
posterior figures draw the sets of the study's own law only, on the inputs they calibrate; a config
without the key draws none. A value outside the prior box is drawn (the axis widened to show it) and
named by `outside_box`, not refused: a published fit need not lie in the box a study chose.
"""

from __future__ import annotations

from dataclasses import dataclass

from shockcal.errors import ConfigError
from shockcal.hydro.laws import get_law
from shockcal.study.strength_config import section_model, strength_model
from shockcal.units import DIMENSIONLESS, unit_factor


@dataclass(frozen=True)
class ReferenceSet:
    """One set to draw: its legend `label`, `citation`, and per study input (the name in `inputs`) its value
    and that value's unit (the unit the law's parameter name carries)."""

    label: str
    citation: str
    values: dict[str, tuple[float, str]]


def _given(config: dict) -> list[dict]:
    return list((config.get("study") or {}).get("reference_sets") or [])


def check_reference_sets(config: dict, source: str) -> None:
    """ConfigError naming the key: a label given twice, or a value named after no parameter of the set's law."""
    labels = set()
    for i, given in enumerate(_given(config)):
        where = f"{source}: study.reference_sets[{i}]"
        if given["label"] in labels:
            raise ConfigError(f"{where}.label: '{given['label']}' is the label of an earlier set")
        labels.add(given["label"])
        law = get_law(section_model(given))
        for name in given["values"]:
            if name not in law.names():
                raise ConfigError(f"{where}.values.{name}: not a parameter of {law.name} "
                                  f"(parameters: {', '.join(law.names())})")


def drawn_sets(config: dict) -> list[ReferenceSet]:
    """The sets of the study's law (`strength.model`), in the config's order, each with the values of the
    study's inputs it gives; a set of another law is left out."""
    model = strength_model(config)
    law = get_law(model)
    sets = []
    for given in _given(config):
        if section_model(given) != model:
            continue
        values = {}
        for name, value in given["values"].items():
            param = law.param(name)
            if law.column(param) in config["inputs"]:      # the study input that holds it (`Law.column`)
                values[law.column(param)] = (float(value), param.unit)
        sets.append(ReferenceSet(given["label"], given.get("citation", ""), values))
    return sets


def outside_box(config: dict) -> list[str]:
    """One line per drawn value outside its input's prior box: the set, the parameter, the value and the box,
    in the parameter's unit."""
    lines = []
    for ref in drawn_sets(config):
        for name, (value, unit) in ref.values.items():
            box = config["inputs"][name]
            dimensionless = box["unit"] in DIMENSIONLESS and unit in DIMENSIONLESS
            factor = 1.0 if dimensionless else unit_factor(box["unit"], unit)
            low, high = box["min"] * factor, box["max"] * factor
            if not low <= value <= high:
                shown = "" if unit in DIMENSIONLESS else f" {unit}"
                lines.append(f"study.reference_sets '{ref.label}': {name} = {value:g}{shown} is outside the "
                             f"prior box [{low:g}, {high:g}]{shown}")
    return lines
