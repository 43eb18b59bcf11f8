"""Placeholders of an external code's input deck and command line, and their rendering.

Syntax: `{name}` in a template file or the command line is replaced by the run's value of `name`;
every name carries its unit (`{A_MPa}`, `{velocity_m_s}`, `{flyer_mm}`; a name without a suffix is
dimensionless, e.g. `{C}`, `{cfl}`). `{name:.6g}` formats with a Python format spec; without one a number
is written as Python's `repr`, the shortest decimal that reads back as the same double (so a deck
loses nothing). `{{` and `}}` are literal braces. A name not in the list below is refused in one line
naming the file and the line (`check_template`), before any run starts.

The names (`placeholder_units`): `run`, `shot`; the strength law's inputs (Johnson-Cook: A_MPa, B_MPa
and, in the design's own units, A_Mbar, B_Mbar; C, n, m; another law: its parameters by their names,
which carry their units); `velocity_m_s`, `velocity_cm_us`; `shear_modulus_GPa`, `shear_modulus_Mbar`
(laws without a G law); the plates `flyer_mm`, `target_mm`, `initial_temperature_K`, the simulated time
`end_time_us`; the `material` and `hydro` settings by their config names (`rho0_g_cc`, `c1_Mbar`,
`cell_size_um`, `output_dt_ns`, ...). The command line also has `python` (the interpreter running
shockcal), `study_dir` (the directory shockcal was started in, absolute) and `run_dir` (the run's folder).
"""

from __future__ import annotations

import string
import sys
from collections.abc import Mapping
from pathlib import Path

from shockcal.design.tables import ShotMapping
from shockcal.errors import ConfigError
from shockcal.hydro import Geometry, HydroSettings, MaterialProperties
from shockcal.hydro.laws import get_law

_JOHNSON_COOK = {"A_MPa": "MPa", "B_MPa": "MPa", "A_Mbar": "Mbar", "B_Mbar": "Mbar", "C": "-", "n": "-", "m": "-"}
_SHOT = {"run": "id", "shot": "name", "velocity_m_s": "m/s", "velocity_cm_us": "cm/us", "flyer_mm": "mm",
         "target_mm": "mm", "initial_temperature_K": "K", "end_time_us": "us"}
_MODULUS = {"shear_modulus_GPa": "GPa", "shear_modulus_Mbar": "Mbar"}
_SUFFIX_UNITS = {"_Mbar": "Mbar", "_GPa": "GPa", "_MPa": "MPa", "_g_cc": "g/cc", "_J_per_kg_K": "J/kg/K", "_K": "K",
                 "_per_s": "1/s", "_g_per_mol": "g/mol", "_um": "um", "_ns": "ns", "_us": "us"}
COMMAND_ONLY = {"python": "path", "study_dir": "path", "run_dir": "path"}


def _unit(name: str) -> str:
    return next((unit for suffix, unit in _SUFFIX_UNITS.items() if name.endswith(suffix)), "-")


def placeholder_units(mapping: ShotMapping) -> dict[str, str]:
    """Every placeholder a run of a shot read by `mapping` has, name -> unit ("-" dimensionless)."""
    names = dict(_SHOT)
    if get_law(mapping.model).code_unit_columns:     # Johnson-Cook: its MPa names and its design's Mbar ones
        names.update(_JOHNSON_COOK)
    else:
        names.update({name: _unit(name) for name in mapping.strength_inputs})
    if mapping.shear_modulus_inputs:
        names.update(_MODULUS)
    names.update({name: _unit(name) for name in MaterialProperties.model_fields})
    names.update({name: _unit(name) for name in HydroSettings.model_fields})
    return names


def run_values(mapping: ShotMapping, row: Mapping, geometry: Geometry, material: MaterialProperties,
               settings: HydroSettings) -> dict:
    """The placeholders' values for one design row (`row`: run and the shot's inputs, Table IV units)."""
    params = mapping.parameters(row)
    values = {"run": int(row["run"]), "shot": mapping.shot, "velocity_m_s": params.velocity_m_s,
              "flyer_mm": geometry.flyer_mm, "target_mm": geometry.target_mm, "end_time_us": geometry.end_us,
              "initial_temperature_K": (material.T_ref_K if geometry.initial_temperature_K is None
                                        else geometry.initial_temperature_K),
              **material.model_dump(), **settings.model_dump()}
    values["velocity_cm_us"] = float(row[mapping.velocity_input])
    if get_law(mapping.model).code_unit_columns:
        exact = params.table_iv()
        values.update(A_MPa=params.A_MPa, B_MPa=params.B_MPa, A_Mbar=exact.A_Mbar, B_Mbar=exact.B_Mbar, C=exact.C,
                      n=exact.n, m=exact.m, shear_modulus_Mbar=exact.shear_modulus_Mbar)
    else:
        values.update({name: float(row[name]) for name in mapping.strength_inputs})
        if params.shear_modulus_GPa is not None:
            values["shear_modulus_Mbar"] = float(sum(float(row[k]) for k in mapping.shear_modulus_inputs))
    if params.shear_modulus_GPa is not None:
        values["shear_modulus_GPa"] = params.shear_modulus_GPa
    return values


def command_values(run_dir: Path) -> dict:
    """The command line's own placeholders: `python`, `study_dir`, `run_dir`."""
    return {"python": sys.executable, "study_dir": str(Path.cwd().resolve()), "run_dir": str(Path(run_dir).resolve())}


def check_template(text: str, known: Mapping[str, str], where: str) -> None:
    """A ConfigError naming `where`, the line and the placeholder when `text` has a placeholder not in
    `known`, a conversion (`!r`) or an unbalanced brace."""
    for number, line in enumerate(text.splitlines(), start=1):
        try:
            parsed = list(string.Formatter().parse(line))
        except ValueError as exc:
            raise ConfigError(f"{where}: line {number}: {exc} (a literal brace is written {{{{ or }}}})") from None
        for _, name, spec, conversion in parsed:
            if name is None:
                continue
            if name not in known:
                raise ConfigError(f"{where}: line {number}: unknown placeholder {{{name}}}; known: "
                                  f"{', '.join(f'{k} ({u})' for k, u in known.items())}")
            if conversion:
                raise ConfigError(f"{where}: line {number}: {{{name}!{conversion}}}: conversions are not supported; "
                                  "give a format spec instead, e.g. {" + name + ":.6g}")
            if "{" in (spec or ""):
                raise ConfigError(f"{where}: line {number}: {{{name}:{spec}}}: nested placeholders are not supported")


def render(text: str, values: Mapping) -> str:
    """`text` with its placeholders replaced by `values` (checked before by `check_template`); a number
    without a format spec is written as its `repr` (round-trips a double exactly)."""
    out = []
    for literal, name, spec, _ in string.Formatter().parse(text):
        out.append(literal)
        if name is None:
            continue
        value = values[name]
        if spec:
            out.append(format(value, spec))
        else:
            out.append(repr(float(value)) if isinstance(value, float) else str(value))
    return "".join(out)
