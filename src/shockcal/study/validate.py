"""Study configuration: load YAML, validate against the JSON schema, check cross-field rules.

The schema (src/shockcal/config.schema.yaml, also used by the Snakefile) fills defaults and
checks types and ranges; `check_semantics` adds the rules a schema cannot express, and
`check_design_file` reads the config's design file through the study's own design loader. Relative paths
in a config (design.file, observed.records.*.path) are relative to the working directory, which
for the workflow is the repository root.
"""

from __future__ import annotations

import difflib
from collections.abc import Mapping
from pathlib import Path

import yaml

from shockcal.errors import ConfigError, InputError, ShockcalError
from shockcal.hydro import rules
from shockcal.hydro.material_library import resolve_material
from shockcal.study.config_checks import check_design_file, check_model_sections, check_semantics, expand_candidate_grid
from shockcal.study.config_files import (
    check_filled,
    load_schema,
    merge_config_files,
    merge_into,
    shown_path,
)
from shockcal.study.references import check_reference_sets
from shockcal.study.report_notes import check_report_notes
from shockcal.study.simulator_rules import check_simulator
from shockcal.study.strength_config import apply_strength_model


def load_config(path: str | Path) -> dict:
    """Read a study config file (through its `extends` chain, `shockcal.study.config_files`), fill schema
    defaults and reject anything invalid, naming the file that sets the key."""
    config, files = merge_config_files([path])
    try:
        return validate_config(config, CONFIG_SOURCE)
    except ConfigError as exc:
        raise ConfigError(_name_source(str(exc), [str(f) for f in files], {})) from None


def validate_config(config: dict, source: str = "config") -> dict:
    """Validate a config mapping in place (schema + semantics) and return it."""
    from jsonschema.exceptions import ValidationError

    check_filled(config, source)
    _normalise_shot_names(config)
    resolve_config_material(config, source)
    try:
        _schema_validator().validate(config)
    except ValidationError as exc:
        raise ConfigError(f"{source}: {_schema_message(exc)}") from None
    check_model_sections(config, source)
    apply_strength_model(config, source)
    expand_candidate_grid(config, source)
    check_semantics(config, source)
    check_reference_sets(config, source)
    check_report_notes(config, source)
    check_simulator(config, source)
    check_design_file(config, source)
    return config


def resolve_config_material(config: dict, source: str = "config") -> None:
    """`material` in place: its library entry (`name`) under its keys and its EOS as the cubic
    (`shockcal.hydro.material_library.resolve_material`), before the schema checks it, so every stage reads one form.
    A bad name or EOS form is a ConfigError naming the key; a section that is not a mapping is the schema's."""
    if isinstance(config.get("material"), Mapping):
        try:
            config["material"] = resolve_material(config["material"])
        except InputError as exc:
            raise ConfigError(f"{source}: {exc}") from None


def _schema_validator():
    """A JSON Schema (2020-12) validator of config.schema.yaml that also fills each missing key's
    `default:` before checking it, as jsonschema's FAQ describes (and snakemake's `validate` does), and
    checks `x-rule: <name>` with the hydrocode's own rule of that name (`shockcal.hydro.rules`), so the
    config and the library refuse the same values in the same words."""
    import copy

    from jsonschema import Draft202012Validator, ValidationError, validators

    check_properties = Draft202012Validator.VALIDATORS["properties"]

    def check_rule(validator, rule, instance, schema):
        if validator.is_type(instance, "number"):
            problem = rules.problem(instance, rule)
            if problem:
                yield ValidationError(problem)

    def fill_defaults(validator, properties, instance, schema):
        if isinstance(instance, dict):
            for name, subschema in properties.items():
                if "default" in subschema and name not in instance:
                    instance[name] = copy.deepcopy(subschema["default"])
        yield from check_properties(validator, properties, instance, schema)

    schema = load_schema()
    return validators.extend(Draft202012Validator, {"properties": fill_defaults, "x-rule": check_rule})(schema)


def workflow_config_or_exit(config: dict, configfiles: list[str], overrides: dict, default: str) -> list[str]:
    """The Snakefile's config: the study the `configfiles` (snakemake's --configfile, in order; `default`
    when none is given) stand for, through their `extends` chains (`merge_config_files`), with snakemake's
    --config `overrides` on top, put in place of `config`'s contents and validated (`validate_or_exit`).
    A bad file ends snakemake with its one line. Returns the files merged, in order."""
    try:
        merged, files = merge_config_files(list(configfiles) or [default])
    except ShockcalError as exc:
        raise SystemExit(f"shockcal: error: {exc}") from None
    config.clear()
    config.update(merge_into(merged, overrides))
    files = [str(path) for path in files]
    validate_or_exit(config, files=files, overrides=overrides)
    return files


def validate_or_exit(config: dict, files: list[str] | None = None, overrides: dict | None = None) -> dict:
    """`validate_config` for the Snakefile: a bad config or design ends snakemake with the message alone
    (SystemExit), where an exception would print a traceback around it. `files` are the config files
    merged into `config`, later ones overriding (`workflow_config_or_exit`), `overrides` snakemake's --config
    values, which override them all; the message names the one that sets the key at fault (`config_source_of`)."""
    try:
        return validate_config(config, CONFIG_SOURCE)
    except ConfigError as exc:
        raise SystemExit(f"shockcal: error: {_name_source(str(exc), files or [], overrides or {})}") from None
    except ShockcalError as exc:
        raise SystemExit(f"shockcal: error: {exc}") from None


CONFIG_SOURCE = "config"     # what a merged config's messages start with, before `_name_source` names the file


def _name_source(message: str, files: list[str], overrides: dict) -> str:
    """A message 'config: key.path: reason' with 'config' replaced by the file that sets key.path."""
    prefix = f"{CONFIG_SOURCE}: "
    if not message.startswith(prefix) or not files:
        return message
    key = message[len(prefix):].split(": ", 1)[0]
    return config_source_of(key, files, overrides) + message[len(CONFIG_SOURCE):]


def config_source_of(key: str, files: list[str], overrides: dict | None = None) -> str:
    """Which source of a merged config sets the dotted `key` (`a.b[0]` reads as `a.b`): among `files`
    (later ones overriding) and then snakemake's --config `overrides`, the one that holds the longest part
    of its path, the later on a tie; when none holds any of it (a default), all the files joined by ' + '."""
    parts = key.split("[")[0].split(".")
    sources = [(shown_path(path), lambda path=path: yaml.safe_load(Path(path).read_text(encoding="utf-8-sig")))
               for path in files]
    sources.append(("snakemake --config", lambda: overrides))
    best, depth = " + ".join(map(shown_path, files)), 0
    for name, load in sources:
        try:
            node = load()
        except (OSError, yaml.YAMLError, UnicodeDecodeError):
            continue
        held = 0
        for part in parts:
            match = [v for k, v in node.items() if str(k) == part] if isinstance(node, Mapping) else []
            if not match:
                break
            node, held = match[0], held + 1
        if held and held >= depth:
            best, depth = name, held
    return best


def _normalise_shot_names(config: dict) -> None:
    """YAML reads an unquoted shot name like 104 as an int; shot names are strings. It runs before the
    schema check, so it assumes no shape: a section of the wrong type is left for the schema to name."""
    observed = _section(config, "observed")
    for section in (_section(config, "shots"), _section(observed, "features"), _section(observed, "records")):
        for key in [k for k in section if not isinstance(k, str)]:
            section[str(key)] = section.pop(key)
    design = _section(config, "design")
    if isinstance(design.get("base_shots"), list):
        design["base_shots"] = [str(shot) if isinstance(shot, int) else shot for shot in design["base_shots"]]
    next_shot = _section(config, "next_shot")
    for spec in [*_section(next_shot, "candidates").values(), next_shot.get("grid")]:
        if isinstance(spec, dict) and isinstance(spec.get("shot"), int):     # a candidate's reference shot
            spec["shot"] = str(spec["shot"])


def _section(mapping: dict, key: str) -> dict:
    """`mapping[key]` when both are mappings, else an empty one (a shape the schema check will name)."""
    section = mapping.get(key) if isinstance(mapping, dict) else None
    return section if isinstance(section, dict) else {}


def _schema_message(exc) -> str:
    """Turn a jsonschema error into 'key.path: reason': an unknown key with the known keys closest to it
    ("did you mean"), a value matching none of a key's alternatives with each alternative's reason."""
    key = ".".join(str(p) for p in exc.absolute_path) or "<top level>"
    message = exc.message
    if exc.validator == "additionalProperties" and isinstance(exc.instance, dict) and "properties" in exc.schema:
        known = list(exc.schema["properties"])
        close = {k: difflib.get_close_matches(str(k), known, n=1) for k in exc.instance if k not in known}
        message += "".join(f"; did you mean '{match[0]}' for '{k}'?" if len(close) > 1 else
                           f"; did you mean '{match[0]}'?" for k, match in close.items() if match)
    elif exc.validator == "oneOf" and exc.context:
        message = "; or ".join(dict.fromkeys(sub.message for sub in exc.context))
    elif exc.validator == "type" and isinstance(exc.instance, list | dict):      # the value itself may be long
        expected = exc.validator_value if isinstance(exc.validator_value, list) else [exc.validator_value]
        message = (f"{SCHEMA_TYPES[type(exc.instance).__name__]} given, but it must be "
                   f"{' or '.join(SCHEMA_TYPES.get(t, t) for t in expected)}")
    return f"{key}: {message}"


# JSON Schema's types as a YAML writer sees them (and Python's list and dict)
SCHEMA_TYPES = {"object": "a mapping (key: value)", "array": "a list", "null": "null", "dict": "a mapping",
                "list": "a list", "number": "a number", "string": "a string", "integer": "an integer",
                "boolean": "true or false"}
