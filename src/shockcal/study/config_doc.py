"""docs/configuration.md, every config key on one page, rendered from config.schema.yaml.

A row per schema property (key path, type, default, unit, range or choices, meaning, reruns): the
meaning is the property's `description`, the unit its `x-unit` or its name's unit suffix (`_us`,
`_Mbar`, ...), and "reruns" is worked out from the declarations that drive the workflow's rerun
triggers: `shockcal.study.stages.STAGE_KEYS` and what each figure's catalogue entry `reads`. Nothing on
the page is written by hand, so page and schema cannot drift (tests/test_config_doc.py).
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

from shockcal.errors import ConfigError
from shockcal.hydro.rules import RULES
from shockcal.study.config_files import load_schema

DOC_PATH = Path("docs") / "configuration.md"   # relative to the repository root

# how a key of a free-form mapping (`additionalProperties`) is written in a key path
PLACEHOLDERS = {"shots": "<shot>", "inputs": "<input>", "observed.features": "<shot>", "observed.records": "<shot>",
                "calibration.cube_power": "<input>", "strength.inputs": "<parameter>",
                "next_shot.candidates": "<candidate>", "next_shot.readout_sd_m_s": "<feature>",
                "simulator.command.env": "<variable>", "simulator.archive.features": "<shot>",
                "simulator.archive.traces": "<shot>", "study.report_notes": "<caption>",
                "study.reference_sets[].values": "<parameter>"}
# unit suffixes of key names (shockcal's "units in names"), longest match first
UNIT_SUFFIXES = (("_J_per_kg_K", "J/(kg K)"), ("_per_s", "1/s"), ("_per_K", "1/K"), ("_g_cc", "g/cc"),
                 ("_g_per_mol", "g/mol"), ("_Mbar", "Mbar"), ("_mm", "mm"), ("_um", "um"), ("_us", "us"), ("_ns", "ns"),
                 ("_K", "K"))
# STAGE_KEYS path segments that stand for any key, and what they say about which jobs rerun
WILDCARDS = {"*": "", "{shot}": "its shot", "{shot_inputs}": "shots that read it", "{names}": ""}
# the figure catalogue lists the figures of a config's shots: three stand-ins, each with a record, give every figure
FIGURE_SHOTS = {"shots": {"S1": {}, "S2": {}, "S3": {}}, "observed": {"records": {"S1": {}, "S2": {}, "S3": {}}}}

HEADER = """\
# Configuration reference

<!-- Generated from src/shockcal/config.schema.yaml by `shockcal config-doc --out docs/configuration.md`:
     edit the schema, not this page (tests/test_config_doc.py compares them). -->

Every key of a study config (a complete one such as `config/config.yaml` or the one `shockcal init` writes,
and overlays such as `config/quick.yaml`, which name the config they overlay with a top-level `extends:`,
read before validation; docs/workflow.md), from the JSON Schema that the Snakefile and every `shockcal`
command validate a config against. `<shot>` and `<input>` stand for the names under `shots` and `inputs`.

- **default**: what validation fills in when the key is left out; *required*: the key must be given.
- **unit**: the key's unit (from its name's suffix or the schema's `x-unit`); blank: a count, a name,
  a switch or a dimensionless number.
- **range**: bounds (`(0, 1]`: above 0, at most 1) or the allowed values.
- **reruns**: the stages whose declared keys (`shockcal.study.stages.STAGE_KEYS`; docs/workflow.md, "What
  reruns when") include the key, so a change reruns their jobs through the rules' params; "(its shot)"
  means only the jobs of the shot whose key changed, "(shots that read it)" those of the shots whose
  `velocity_input` or `shear_modulus_inputs` name the input. `figures 9, 10` are the figures (the
  paper's numbers) whose catalogue entry reads the key (`FigureSpec.reads`). Snakemake then reruns
  whatever reads a rerun job's changed outputs. *none declared*: no stage lists the key; its meaning
  says what the workflow does with it.
"""


@dataclass(frozen=True)
class Key:
    """One schema property: its key path (`PLACEHOLDERS` for free-form keys), its schema with any
    `$ref` resolved, and whether its parent requires it."""

    path: tuple[str, ...]
    schema: dict
    required: bool

    @property
    def name(self) -> str:
        return ".".join(self.path)



def schema_keys(schema: dict) -> list[Key]:
    """Every property of `schema`, depth first in the schema's order, free-form mappings included."""
    return list(_walk(schema, schema, ()))


def undescribed(schema: dict) -> list[str]:
    """Key paths of the properties that have no `description`."""
    return [key.name for key in schema_keys(schema) if not str(key.schema.get("description", "")).strip()]


def reruns(path: tuple[str, ...], stage_keys: dict[str, tuple[str, ...]] | None = None,
           figure_reads: dict[str, tuple[str, ...]] | None = None) -> str:
    """Which stages (and figures) a change of the key at `path` reruns, from `stage_keys` (default
    `documented_stage_keys()`) and the figures' `reads` (default: the catalogue's), as the page writes it."""
    from shockcal.study.stages import documented_stage_keys

    stage_keys = documented_stage_keys() if stage_keys is None else stage_keys
    figure_reads = _figure_reads() if figure_reads is None else figure_reads
    parts = []
    for stage, declared in stage_keys.items():
        scopes = {_scope(d.split(".")) for d in declared if _overlaps(path, d.split("."))}
        if scopes:
            parts.append(stage if "" in scopes else f"{stage} ({', '.join(sorted(scopes))})")
    if "figures" not in parts:
        figures = [name for name, reads in figure_reads.items() if any(_overlaps(path, r.split(".")) for r in reads)]
        if figures:
            parts.append("figures " + _figure_numbers(figures))
    return "; ".join(parts) or "*none declared*"


def render(schema: dict | None = None) -> str:
    """The Markdown page: `HEADER`, then a section per top-level key with a table of its keys."""
    schema = load_schema() if schema is None else schema
    missing = undescribed(schema)
    if missing:
        raise ConfigError(f"config.schema.yaml: {missing[0]} has no description ({len(missing)} keys without one)")
    figure_reads = _figure_reads()
    lines = [HEADER]
    keys = schema_keys(schema)
    for section in (key for key in keys if len(key.path) == 1):
        lines += ["", f"## `{section.name}`", "", _markdown(section.schema["description"])
                  + (" Required." if section.required else ""), "",
                  "| key | type | default | unit | range | meaning | reruns |", "|---|---|---|---|---|---|---|"]
        for key in keys:
            if len(key.path) > 1 and key.path[0] == section.path[0]:
                s = key.schema
                lines.append("| " + " | ".join([
                    f"`{key.name}`", _type(s), default_text(s, key.required), unit_text(key), range_text(s),
                    _markdown(s["description"]), reruns(key.path, figure_reads=figure_reads)]) + " |")
    return "\n".join(lines) + "\n"


def _walk(root: dict, node: dict, path: tuple[str, ...]) -> Iterator[Key]:
    required = set(node.get("required", ()))
    for name, sub in node.get("properties", {}).items():
        child = _resolve(root, sub)
        yield Key((*path, name), child, name in required)
        yield from _walk(root, child, (*path, name))
    items = _resolve(root, node["items"]) if isinstance(node.get("items"), dict) else {}
    if path and "properties" in items:     # a list of mappings: its items' keys as `<list>[].<key>`
        yield from _walk(root, items, (*path[:-1], f"{path[-1]}[]"))
    extra = node.get("additionalProperties")
    if isinstance(extra, dict):
        dotted = ".".join(path)
        if dotted not in PLACEHOLDERS:
            raise ConfigError(f"config.schema.yaml: {dotted} holds free-form keys: name them in config_doc.PLACEHOLDERS")
        child = _resolve(root, extra)
        yield Key((*path, PLACEHOLDERS[dotted]), child, False)
        yield from _walk(root, child, (*path, PLACEHOLDERS[dotted]))


def _resolve(root: dict, schema: dict) -> dict:
    """`schema` with its `$ref` (to `#/definitions/...`) merged in, its own keywords winning, and the
    options of a `oneOf` resolved."""
    if "oneOf" in schema:
        schema = {**schema, "oneOf": [_resolve(root, option) for option in schema["oneOf"]]}
    if "$ref" not in schema:
        return schema
    target = root
    for part in schema["$ref"].removeprefix("#/").split("/"):
        target = target[part]
    return {**_resolve(root, target), **{k: v for k, v in schema.items() if k != "$ref"}}


def _overlaps(path: tuple[str, ...], declared: list[str]) -> bool:
    """Whether a key path and a declared path (STAGE_KEYS syntax) share a key: one is the other's prefix,
    segment by segment, a placeholder or wildcard matching any key; an optional key's `?` is dropped."""
    declared = [*declared[:-1], declared[-1].removesuffix("?")] if declared else declared
    if declared and declared[-1] == "{names}" and len(path) > len(declared):
        return False            # the names alone: a key inside one is not read
    return all(k.removesuffix("[]") == d or d in WILDCARDS or k.startswith("<") for k, d in zip(path, declared))


def _scope(declared: list[str]) -> str:
    return next((WILDCARDS[d] for d in declared if WILDCARDS.get(d)), "")


def _figure_numbers(names: list[str]) -> str:
    """['fig02_records', 'fig04_...', 'fig05_...', 'fig06_...'] -> '2, 4-6' (the paper's numbers; other names as
    they are)."""
    numbers = sorted({int(name[3:5]) for name in names if re.match(r"fig\d\d_", name)})
    runs: list[list[int]] = []
    for number in numbers:
        if runs and number == runs[-1][-1] + 1:
            runs[-1].append(number)
        else:
            runs.append([number])
    spans = [", ".join(map(str, run)) if len(run) < 3 else f"{run[0]}-{run[-1]}" for run in runs]
    return ", ".join([*spans, *(name for name in names if not re.match(r"fig\d\d_", name))])


def _figure_reads() -> dict[str, tuple[str, ...]]:
    from shockcal.study.figure_catalogue import catalogue

    return {name: spec.reads for name, spec in catalogue(FIGURE_SHOTS).items()}


def _type(s: dict) -> str:
    if "oneOf" in s:
        return " or ".join(_type(option) for option in s["oneOf"])
    if "const" in s:
        return f"`{s['const']}`"
    kind = s.get("type", "string" if all(isinstance(v, str) for v in s.get("enum", [0])) else "")
    if isinstance(kind, list):
        return " or ".join(kind) if len(kind) < 3 else ", ".join(kind[:-1]) + " or " + kind[-1]
    if kind == "object":
        return "mapping"
    if kind == "array":
        return f"list of {_type(s.get('items', {}))}"
    return kind


def range_text(s: dict) -> str:
    """A schema entry's limits and choices as text (">= 1", "one of `lhs`, `waves`"); "" when it has none."""
    if "oneOf" in s:
        return " or ".join(filter(None, (range_text(option) for option in s["oneOf"])))
    parts = []
    low = ("[", s["minimum"]) if "minimum" in s else ("(", s["exclusiveMinimum"]) if "exclusiveMinimum" in s else None
    high = ("]", s["maximum"]) if "maximum" in s else (")", s["exclusiveMaximum"]) if "exclusiveMaximum" in s else None
    if low and high:
        parts.append(f"{low[0]}{_value(low[1])}, {_value(high[1])}{high[0]}")
    elif low:
        parts.append(f"{'>=' if low[0] == '[' else '>'} {_value(low[1])}")
    elif high:
        parts.append(f"{'<=' if high[0] == ']' else '<'} {_value(high[1])}")
    if s.get("x-rule") and RULES[s["x-rule"]].interval():
        parts.append(RULES[s["x-rule"]].interval())
    if "enum" in s:
        parts.append("one of " + ", ".join(f"`{_value(v)}`" for v in s["enum"]))
    if "enum" in s.get("items", {}):
        parts.append("each one of " + ", ".join(f"`{_value(v)}`" for v in s["items"]["enum"]))
    for keyword, what in (("minItems", "item"), ("minProperties", "key")):
        if keyword in s:
            parts.append(f"at least {s[keyword]} {what}{'s' if s[keyword] != 1 else ''}")
    return "; ".join(parts)


def default_text(s: dict, required: bool) -> str:
    """A schema entry's default as text (in backticks), `*required*` for a required key without one, else ""."""
    if "default" in s:
        return '`""`' if s["default"] == "" else f"`{_value(s['default'])}`"
    return "*required*" if required else ""


def unit_text(key: Key) -> str:
    """A key's unit as text (its `x-unit`, else what its name says)."""
    if "x-unit" in key.schema:
        return _markdown(key.schema["x-unit"])
    return next((unit for suffix, unit in UNIT_SUFFIXES if key.path[-1].endswith(suffix)), "")


def _value(v) -> str:
    """A YAML-like literal: null, true, 0.5, 1e-07, [png, pdf], {}."""
    if v is None:
        return "null"
    if isinstance(v, bool):
        return str(v).lower()
    if isinstance(v, int | float):
        return f"{v:g}"
    if isinstance(v, list):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{k}: {_value(x)}" for k, x in v.items()) + "}"
    return str(v)


def _markdown(text: str) -> str:
    """One table cell: on one line, with `*` and `|` outside code spans escaped."""
    spans = " ".join(str(text).split()).split("`")
    return "`".join(span if i % 2 else span.replace("|", "\\|").replace("*", "\\*") for i, span in enumerate(spans))
