"""Study config files: a complete config, or an overlay naming the config it overlays (`extends:`).

A config file is COMPLETE (a study of its own: it has every top-level key the schema requires) unless it
names the file it overlays with a top-level `extends: <path>`, relative to the overlay's own folder.
Overlays chain (an overlay may extend an overlay) down to one complete config. Several files given
together (snakemake's `--configfile a.yaml b.yaml`) are each resolved through their chains, in order,
each file once at its first place; a later file without `extends` overlays the files before it. This
module is the one place that merges config files: the Snakefile and every `shockcal --config` read a
study through `merge_config_files`. Refused, in one line naming the file: a partial config with no
`extends` where a study must start, an `extends` that does not exist, a cycle, and a complete config
given after another (its shots would be merged with the other study's). `check_filled` refuses a value
`shockcal init` left as its placeholder (`FILL_IN`), before the schema's check.
"""

from __future__ import annotations

import copy
import functools
import os
from pathlib import Path

import yaml

from shockcal.campaign.settings import (
    CandidateShot,
    ModulusSlopeSettings,
    NextShotCheckSettings,
    NextShotSettings,
    SensitivitySettings,
)
from shockcal.design.settings import Bounds, DesignSettings, InputRange, NewShotSettings, WaveSettings
from shockcal.emulator.settings import EmulatorSettings
from shockcal.errors import ConfigError
from shockcal.hydro.laws.settings import StrengthSettings
from shockcal.hydro.settings import HydroSettings, MaterialProperties, Plates
from shockcal.inference.settings import (
    CheckSettings,
    DiscrepancySettings,
    PredictSettings,
    SamplerSettings,
    StepSamplerSettings,
    VerifySettings,
)
from shockcal.plausibility import ChecksSettings
from shockcal.plots.settings import FigureSettings
from shockcal.settings_model import other_sections, schema_properties
from shockcal.simulators.command import CommandSettings
from shockcal.simulators.outputs import OutputSpec
from shockcal.simulators.settings import SimulateSettings
from shockcal.velocimetry.settings import ExtractorSettings, ObservedSettings

EXTENDS = "extends"
SCHEMA_PATH = Path(__file__).parents[1] / "config.schema.yaml"
YAML_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)   # libyaml's safe loader where PyYAML has it: the same result
FILL_IN = "<fill in>"     # the placeholder `shockcal init` writes for a value the study must give


# Config sections whose keys are a library settings model's fields: the schema's entries for them are
# generated from the model (`shockcal.settings_model.schema_properties`), the YAML holds only the rest. A
# field of another section (`setting(section=...)`: ExtractorSettings' analysis window) is generated there. A
# section that is a mapping or a word (`calibration.discrepancy`: none) gets the keys of its mapping form.
MODEL_SECTIONS = {"material": MaterialProperties, "hydro": HydroSettings, "shots.*": Plates, "inputs.*": InputRange,
                  "strength.inputs.*": Bounds, "emulator": EmulatorSettings, "features": ExtractorSettings,
                  "calibration": SamplerSettings, "calibration.check": CheckSettings,
                  "calibration.discrepancy": DiscrepancySettings,
                  "verify": VerifySettings, "design": DesignSettings, "design.new_shots": NewShotSettings,
                  "design.waves": WaveSettings, "design.waves.step_calibration": StepSamplerSettings,
                  "checks": ChecksSettings, "simulate": SimulateSettings, "predict": PredictSettings,
                  "sensitivity": SensitivitySettings, "figures": FigureSettings, "next_shot": NextShotSettings,
                  "next_shot.shear_modulus_log_slope_per_K": ModulusSlopeSettings,
                  "next_shot.check": NextShotCheckSettings, "observed": ObservedSettings, "strength": StrengthSettings,
                  "simulator.command": CommandSettings, "definitions.run_output": OutputSpec,
                  "definitions.candidate": CandidateShot}
AFTER = "x-after"     # a YAML key of such a section placed after this key (the order defaults are filled in)


@functools.lru_cache(maxsize=1)
def _schema_text_parsed() -> dict:
    schema = yaml.load(SCHEMA_PATH.read_text(), Loader=YAML_LOADER)
    for own, model in MODEL_SECTIONS.items():
        for section in [None, *other_sections(model)]:
            entry = section_schema(schema, section or own)
            generated = schema_properties(model, entry.get("required", []), section)
            entry["properties"] = _placed(generated, entry["properties"])
    return schema


def section_schema(schema: dict, section: str) -> dict:
    """The schema entry of config `section` (dotted; `*`: every key of a mapping, e.g. `shots.*.analysis`;
    `definitions.<name>`: a shared entry); of
    a key that is a mapping or something else (`oneOf`), its mapping form's."""
    entry, parts = schema, section.split(".")
    if parts[0] == "definitions":     # a shared entry (`definitions.run_output`), which sections `$ref`
        entry, parts = schema["definitions"][parts[1]], parts[2:]
    for part in parts:
        entry = entry["additionalProperties"] if part == "*" else entry["properties"][part]
    return next((option for option in entry["oneOf"] if option.get("type") == "object"), entry) if "oneOf" in entry \
        else entry


def _placed(generated: dict, written: dict) -> dict:
    """A model section's properties in their order: the model's fields, and each key the YAML writes after
    the key its `x-after` names, else after the YAML key before it (the first one: first). The order is the
    order a validated config holds the section's keys in, which the workflow's rerun triggers compare."""
    keys, previous = list(generated), None
    for name, entry in written.items():
        after = entry.pop(AFTER, previous)
        keys.insert(keys.index(after) + 1 if after is not None else 0, name)
        previous = name
    return {name: generated[name] if name in generated else written[name] for name in keys}


def load_schema() -> dict:
    """The config schema (config.schema.yaml) as a fresh mapping, parsed once per process (a study's config
    is read many times: parsing the schema each time cost 0.2 s a read)."""
    return copy.deepcopy(_schema_text_parsed())


def required_keys() -> list[str]:
    """The top-level keys the schema requires: the keys a complete config holds."""
    return list(_schema_text_parsed()["required"])


def read_config_file(path: str | Path) -> dict:
    """One config file's mapping, as written (no defaults, `extends` kept): a missing file, bad YAML, a
    key given twice or a top level that is not a mapping is a ConfigError naming the file."""
    path = Path(path)
    if not path.is_file():
        raise ConfigError(f"config file {path} does not exist")
    try:
        text = path.read_text(encoding="utf-8-sig")
        config = yaml.load(text, Loader=YAML_LOADER)
        _check_repeated_keys(yaml.compose(text, Loader=YAML_LOADER), path)
    except yaml.YAMLError as exc:
        reason = " ".join(str(exc).split())
        raise ConfigError(f"config file {path} is not valid YAML: {reason}") from None
    except UnicodeDecodeError as exc:
        raise ConfigError(f"config file {path} is not UTF-8 text: {exc}") from None
    if not isinstance(config, dict):
        raise ConfigError(f"config file {path} must hold a mapping at the top level")
    return config


def _check_repeated_keys(node, path, where: str = "") -> None:
    """A key given twice in one mapping (two `104S:` under `shots:`) is a ConfigError naming both lines:
    YAML loaders keep the last one silently."""
    if isinstance(node, yaml.MappingNode):
        seen = {}
        for key, value in node.value:
            name = key.value if isinstance(key, yaml.ScalarNode) else None
            if name is not None and name in seen:
                raise ConfigError(f"config file {path}: {where}{name}: given twice (lines {seen[name]} and "
                                  f"{key.start_mark.line + 1}); YAML would keep only the last")
            if name is not None:
                seen[name] = key.start_mark.line + 1
            _check_repeated_keys(value, path, f"{where}{name}." if name is not None else where)
    elif isinstance(node, yaml.SequenceNode):
        for item in node.value:
            _check_repeated_keys(item, path, where)


def config_chain(path: str | Path) -> list[Path]:
    """The files a config file stands for, the complete one first and `path` last: `path`, the file its
    `extends` names (relative to `path`'s folder), that file's, and so on. A chain that ends in a partial
    config, an `extends` naming no file and a cycle are ConfigErrors naming the file."""
    chain: list[Path] = []
    path = Path(path)
    while True:
        if path.resolve() in [p.resolve() for p in chain]:
            names = " -> ".join(shown_path(p) for p in [*chain, path])
            raise ConfigError(f"{shown_path(chain[-1])}: {EXTENDS}: a cycle ({names}); a chain of overlays ends in a "
                              "complete config")
        chain.append(path)
        parent = read_config_file(path).get(EXTENDS)
        if parent is None:
            check_complete(path)
            return chain[::-1]
        if not isinstance(parent, str) or not parent:
            raise ConfigError(f"{shown_path(path)}: {EXTENDS}: {parent!r} is not a path; give the config file this one "
                              "overlays, relative to this file")
        base = Path(os.path.normpath(path.parent / parent))
        if not base.is_file():
            raise ConfigError(f"{shown_path(path)}: {EXTENDS}: {parent} does not exist (looked for {shown_path(base)})")
        path = base


def check_complete(path: Path) -> None:
    """A config file without `extends` is a study of its own: it holds every key the schema requires."""
    missing = [key for key in required_keys() if key not in read_config_file(path)]
    if missing:
        names = ", ".join(f"`{key}`" for key in missing)
        raise ConfigError(f"{shown_path(path)}: no {names}: a study config is complete, or names the config it "
                          f"overlays with `{EXTENDS}:`")


def config_files(paths: list[str | Path]) -> list[Path]:
    """The files `paths` (in order) stand for, each once, in the order they merge: the first path's chain,
    then each later one's (files already there skipped). A later path without `extends` overlays the files
    before it; a complete config after another is a ConfigError (two studies merged)."""
    if not paths:
        raise ConfigError("no config file given")
    files: list[Path] = []
    for index, path in enumerate(paths):
        path = Path(path)
        written = read_config_file(path)
        if index and written.get(EXTENDS) is None:
            chain = [path]
            if all(key in written for key in required_keys()) and not _listed(path, files):
                raise ConfigError(f"{shown_path(path)}: a complete study config (no `{EXTENDS}:`) given after "
                                  f"{shown_path(files[0])}; its shots and inputs would merge with that study's: give it "
                                  f"alone, or make it an overlay with `{EXTENDS}:`")
        else:
            chain = config_chain(path)
            if files and not _listed(chain[0], files):
                raise ConfigError(f"{shown_path(path)}: overlays {shown_path(chain[0])}, and {shown_path(files[0])} is another "
                                  "study config; overlays given together overlay one study")
        files += [p for p in chain if not _listed(p, files)]
    return files


def merge_config_files(paths: list[str | Path]) -> tuple[dict, list[Path]]:
    """The study config `paths` stand for (`config_files`), merged as snakemake merges config files
    (mappings key by key, any other value replaced; `extends` dropped), and the files in merge order.
    Not validated: `shockcal.study.validate.validate_config` fills the defaults and checks it."""
    files = config_files(paths)
    config: dict = {}
    for path in files:
        overlay = read_config_file(path)
        overlay.pop(EXTENDS, None)
        merge_into(config, overlay)
    return config, files


def merge_into(config: dict, overlay: dict) -> dict:
    """`overlay` merged into `config` in place: a mapping over a mapping key by key, any other value
    (a list, null) replacing what was there (snakemake's `update_config`). Returns `config`."""
    for key, value in overlay.items():
        if isinstance(value, dict) and isinstance(config.get(key), dict):
            merge_into(config[key], value)
        else:
            config[key] = copy.deepcopy(value)
    return config


def _listed(path: Path, files: list[Path]) -> bool:
    return path.resolve() in [p.resolve() for p in files]


def shown_path(path: str | Path) -> str:
    """`path` relative to the working directory when it lies inside it (snakemake makes config files absolute)."""
    relative = os.path.relpath(path)
    return str(path) if relative.startswith("..") else relative


def check_filled(config: dict, source: str = "config") -> None:
    """A ConfigError naming the first key that still holds the placeholder `FILL_IN`, or a placeholder
    name (`<shot>`, `V_<shot>`): a starting config from `shockcal init` not filled in yet."""
    problem = _placeholder(config, "")
    if problem:
        raise ConfigError(f"{source}: {problem}")


def _placeholder(node, where: str) -> str | None:
    if isinstance(node, dict):
        for key, value in node.items():
            path = f"{where}.{key}" if where else str(key)
            if isinstance(key, str) and "<" in key and key.endswith(">"):
                return f"{path}: a placeholder name from `shockcal init`; give your own (a shot's or an input's)"
            problem = _placeholder(value, path)
            if problem:
                return problem
    elif isinstance(node, list):
        return next(filter(None, (_placeholder(item, where) for item in node)), None)
    elif node == FILL_IN:
        return f"{where}: still {FILL_IN} (from `shockcal init`); give its value"
    return None
