"""The starting config `shockcal init` writes: every key of the config schema with its default, unit and
meaning, and the keys a study must give marked `<fill in>`.

Generated from src/shockcal/config.schema.yaml through `shockcal.study.config_doc` (the source of
docs/configuration.md), so the two cannot drift. A key with a default is written with it; a required key
without one is the placeholder `FILL_IN`, which `shockcal.study.config_files.check_filled` refuses in one line naming the key until it is
replaced; an optional key without a default (a section that only some studies use, such as simulator.command)
is written commented out. Free-form mappings (shots, inputs, observed.records) get one example entry of
placeholders, with each placeholder key named `<shot>`, `<input>`.
"""

from __future__ import annotations

import textwrap

from shockcal.study.config_doc import Key, default_text, load_schema, range_text, schema_keys, unit_text
from shockcal.study.config_files import FILL_IN

WIDTH = 110
# the free-form mappings a new study fills in (one example entry each); the others stay empty
FILLED_MAPPINGS = {"shots": "<shot>", "inputs": "<input>", "observed.records": "<shot>"}

# the inputs' example entries: Johnson-Cook's A, B, C, n, m (the hydrocode reads stresses in Mbar) and one shot's
# impact velocity and shear modulus (a shot names them in velocity_input and shear_modulus_inputs)
INPUT_EXAMPLES = (("A", "Mbar", "Johnson-Cook yield stress (1 MPa = 1e-5 Mbar)"), ("B", "Mbar", "hardening modulus"),
                  ("C", "-", "strain-rate sensitivity"), ("n", "-", "hardening exponent"),
                  ("m", "-", "thermal-softening exponent"),
                  ("V_<shot>", "cm/us", "the shot's impact velocity (1 cm/us = 1e4 m/s)"),
                  ("G", "Mbar", "shear modulus (1 GPa = 0.01 Mbar)"))

HEADER = """\
# A shockcal study config, written by `shockcal init`: a complete study of its own (no `extends:`).
# Every key of the config schema is here with its default, unit and meaning (docs/configuration.md is the
# same list as a table). Replace each {fill} (the material, the shots, the prior box of the inputs, the
# records), rename each <shot> and <input> to your own names, then run the study from the repository:
#   snakemake --cores all --configfile {path}
# Paths in this file (records, design.file) are relative to the directory snakemake runs in.
"""


def render_template(path_shown: str = "config.yaml", name: str = "my-study", material: str | None = None) -> str:
    """The starting config's text.

    Args:
        path_shown: the file's path, in the header's snakemake line.
        name: the study's name (study.name; results go to results/<name>).
        material: a material of the library (`shockcal materials`): `material.name` is written with it and
            the section's other keys commented out with the entry's values (to override one, uncomment
            it); None: every material key to fill in.
    """
    keys = schema_keys(load_schema())
    by_path = {key.path: key for key in keys}
    entry = _library_material(material)
    lines = [HEADER.format(fill=FILL_IN, path=path_shown)]
    for key in keys:
        if _hidden(key):
            continue
        if entry is not None and key.path[0] == "material" and len(key.path) > 1:
            lines += _key_lines(key, key.path != ("material", "name"), name, _entry_value(entry, key.path[1:]))
        else:
            lines += _key_lines(key, _commented(key, by_path), name)
        if key.path == ("inputs",):
            lines += [f"  {entry}: {{min: {FILL_IN}, max: {FILL_IN}, unit: {unit}}}   # {about}"
                      for entry, unit, about in INPUT_EXAMPLES]
    return "\n".join(lines) + "\n"


def _hidden(key: Key) -> bool:
    """Keys inside a free-form mapping that stays empty (its default `{}` is written), inside a list of
    mappings (its default `[]` is written) or inside the inputs (the named examples `INPUT_EXAMPLES`) are
    left out."""
    if any(part.endswith("[]") for part in key.path):
        return True                       # a list's items (study.reference_sets): the list's default is written
    for depth in range(1, len(key.path)):
        dotted = ".".join(key.path[:depth])
        if key.path[depth].startswith("<") and (dotted not in FILLED_MAPPINGS or dotted == "inputs"):
            return True
    return False


def _commented(key: Key, by_path: dict) -> bool:
    """Whether `key` is written commented out: it or a section holding it is optional and has no default
    (a section only some studies use, such as simulator or next_shot.grid)."""
    for depth in range(1, len(key.path) + 1):
        if key.path[depth - 1].startswith("<"):
            continue
        node = by_path[key.path[:depth]]
        if not node.required and "default" not in node.schema:
            return True
    return False


def _library_material(material: str | None) -> dict | None:
    """The library entry's material section, with its name (an unknown name: an InputError listing them)."""
    if material is None:
        return None
    from shockcal.hydro.material_library import library_entry

    return {"name": material, **library_entry(material, "--material")["material"]}


def _entry_value(entry: dict, path: tuple[str, ...]) -> str:
    node = entry
    for part in path:
        if not isinstance(node, dict) or part not in node:
            return FILL_IN
        node = node[part]
    return _yaml(node)


def _key_lines(key: Key, commented: bool, name: str, value: str | None = None) -> list[str]:
    indent = "  " * (len(key.path) - 1)
    mark = "# " if commented else ""
    about = _about(key)
    description = " ".join(str(key.schema.get("description", "")).split())
    lines = []
    if len(key.path) == 1:
        lines.append("")
    lines += [f"{indent}# {line}" for line in textwrap.wrap(description, WIDTH - len(indent) - 2)]
    label = key.path[-1]
    if "properties" in key.schema or ".".join(key.path) in FILLED_MAPPINGS:
        lines.append(f"{indent}{mark}{label}:" + (f"   # {about}" if about else ""))
        return lines
    value = _value_of(key, name) if value is None else value
    lines.append(f"{indent}{mark}{label}: {value}" + (f"   # {about}" if about else ""))
    return lines


def _value_of(key: Key, name: str) -> str:
    if key.path == ("study", "name"):
        return name
    if key.path == ("study", "results_dir"):
        return f"results/{name}"
    if "default" in key.schema:
        return _yaml(key.schema["default"])
    return FILL_IN


def _yaml(value) -> str:
    """`value` as YAML reads it back (flow style: 1.0e-07, not 1e-07, which YAML 1.1 reads as text)."""
    import yaml

    return yaml.safe_dump(value, default_flow_style=True, width=10**6).removesuffix("\n...\n").strip()


def _about(key: Key) -> str:
    """The inline comment: unit, range, and 'required' or the default when the value shown is not it."""
    parts = [unit_text(key), range_text(key.schema)]
    if key.required and "default" not in key.schema:
        parts.append("required")
    elif "default" in key.schema and key.path in (("study", "name"), ("study", "results_dir")):
        parts.append(f"default {default_text(key.schema, key.required)}")
    return "; ".join(part for part in parts if part)
