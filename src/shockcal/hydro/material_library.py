"""A small library of materials, one data file each (src/shockcal/materials/<name>.yaml, shipped with the
package, its sources cited in it), and the one resolver of a `material` section that both the study config
and the library use.

A section names a library entry and overrides it key by key, its EOS in either form
(`shockcal.hydro.hugoniot.cubic_eos`):

    material: {name: copper}                              # the library's OFHC copper
    material: {name: copper, T_melt_K: 1350}              # with one key changed
    material: {name: copper, eos: {s: 1.5}}               # an EOS key changed (the Us-up form's s)
    material: {name: al5083, eos: {c0_km_s: 5.38, s: 1.33}}   # the other form: replaces the entry's cubic

`resolve_material` returns the section with the entry's keys filled in and its EOS as the cubic the
hydrocode uses, so every stage sees one form; `material_properties` builds `MaterialProperties` from a
section, `load_material("al5083")` from a name. docs/materials.md lists the entries and their sources.
"""

from __future__ import annotations

import copy
import functools
from collections.abc import Mapping
from pathlib import Path

import yaml

from shockcal.errors import InputError
from shockcal.hydro.hugoniot import CUBIC_KEYS, HUGONIOT_KEYS, cubic_eos
from shockcal.hydro.settings import MaterialProperties
from shockcal.settings_model import SettingsError

LIBRARY_DIR = Path(__file__).parents[1] / "materials"


def material_names() -> list[str]:
    """The library's material names (its data files' stems), sorted."""
    return sorted(path.stem for path in LIBRARY_DIR.glob("*.yaml"))


@functools.cache
def _read_entry(name: str) -> dict:
    return yaml.safe_load((LIBRARY_DIR / f"{name}.yaml").read_text(encoding="utf-8"))


def library_entry(name: str, where: str = "material.name") -> dict:
    """The library's entry `name`: {name, description, source, material: {rho0_g_cc, eos, ...}} (a copy).
    An unknown name is an InputError naming `where` and listing the known names."""
    if not isinstance(name, str) or name not in material_names():
        raise InputError(f"{where}: unknown material {name!r}; the library has {', '.join(material_names())}")
    return copy.deepcopy(_read_entry(name))


def resolve_material(section: Mapping, where: str = "material") -> dict:
    """A `material` section with its library entry (`name`, if given) under it and its EOS as the cubic.

    The section's keys override the entry's key by key, `eos` keys too; an `eos` override in the other
    form than the entry's (the cubic's c1_Mbar.. against the Us-up c0_km_s, s) replaces the entry's form
    (its gamma0 stays unless given). The EOS is then converted by `shockcal.hydro.hugoniot.cubic_eos` (both
    forms at once, a partial form: an InputError naming the key). Keys of neither kind are left for the
    caller to refuse (the schema, `material_properties`). `name: null` names no entry (an overlay giving a
    whole material over a named one). A resolved section resolves to itself.

    Args:
        section: the material section (a mapping).
        where: its name in messages ('material').
    """
    resolved = dict(section)
    if "name" in resolved and resolved["name"] is None:      # an overlay's `name: null`: no library entry
        del resolved["name"]
    if "name" in resolved:
        base = library_entry(resolved["name"], f"{where}.name")["material"]
        overrides = resolved
        resolved = {"name": overrides["name"], **base,
                    **{k: v for k, v in overrides.items() if k not in ("name", "eos")}}
        if "eos" in overrides:
            resolved["eos"] = _override_eos(base["eos"], overrides["eos"])
    if isinstance(resolved.get("eos"), Mapping):
        resolved["eos"] = cubic_eos(resolved["eos"], resolved.get("rho0_g_cc"), f"{where}.eos")
    return resolved


def _override_eos(base: Mapping, override):
    """The entry's EOS `base` with `override`'s keys; an override in the other form drops the base's form."""
    if not isinstance(override, Mapping):
        return override
    for form in (CUBIC_KEYS, HUGONIOT_KEYS):
        if any(k in override for k in form) and not any(k in base for k in form):
            base = {k: v for k, v in base.items() if k == "gamma0"}
    return {**base, **override}


def material_properties(section: Mapping, where: str = "material") -> MaterialProperties:
    """`MaterialProperties` from a material section in any form `resolve_material` takes (a library name with
    overrides, the cubic or the Us-up EOS); a missing or unknown key is an InputError naming it."""
    resolved = resolve_material(section, where)
    eos = resolved.get("eos")
    if not isinstance(eos, Mapping):
        raise InputError(f"{where}.eos: missing; give the cubic ({', '.join(CUBIC_KEYS)}) or the Us-up Hugoniot "
                         f"({', '.join(HUGONIOT_KEYS)}), each with gamma0")
    flat = {**{k: v for k, v in resolved.items() if k not in ("name", "eos")}, **eos}
    try:
        return MaterialProperties(**flat)
    except SettingsError as error:
        raise InputError(f"{where}.{error.field}: {error.reason}") from None


def load_material(name: str, **overrides) -> MaterialProperties:
    """The library's material `name` (`material_names()`), keys overridden by `overrides` as a config's
    section would (`load_material("copper", T_melt_K=1350.0)`)."""
    return material_properties({"name": name, **overrides})
