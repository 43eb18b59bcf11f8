"""Bad configs are rejected up front, with the key path and the reason in the message."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from shockcal.errors import ConfigError
from shockcal.study.config import shot_config
from shockcal.study.config_files import MODEL_SECTIONS
from shockcal.study.validate import load_config, validate_config

REPO = Path(__file__).resolve().parents[1]


def _set(config: dict, path: str, value) -> None:
    *parents, last = path.split(".")
    node = config
    for key in parents:
        node = node[key]
    node[last] = value


def test_paper_config_is_valid(paper_config):
    validate_config(paper_config)
    assert list(paper_config["shots"]) == ["104S", "105S", "106S"]


@pytest.mark.parametrize(
    "path, value, message",
    [
        ("hydro.cell_size_um", "four", r"hydro\.cell_size_um: 'four' is not of type 'number'"),
        ("shots.104S.target_mm", -2.0, r"shots\.104S\.target_mm: -2 is not a positive number"),
        ("simulate.chunk_size", 0, r"simulate\.chunk_size: 0 is less than the minimum of 1"),
        ("sensitivity.n_base", 1000, r"sensitivity\.n_base: 1000 is not a power of 2"),
        ("predict.end_time_us", 0, r"predict\.end_time_us: 0 is not a positive number"),
        ("inputs.A.min", 0.02, r"inputs\.A\.min: 0\.02 is not below max \(0\.01\)"),
        ("inputs.B.min", -0.001, r"inputs\.B\.min: -0\.001 is negative; Johnson-Cook parameters cannot be negative"),
        ("shots.105S.velocity_input", "V9", r"shots\.105S\.velocity_input: 'V9' is not one of the inputs"),
        ("observed.records", {"104S": {"path": "no/such/record.txt"}},
         r"observed\.records\.104S\.path: no/such/record\.txt does not exist"),
        ("design.file", "no/such/design.csv", r"design\.file: no/such/design\.csv does not exist"),
        ("calibration.cube_power", {"M": 2}, r"calibration\.cube_power\.M: not one of the inputs"),
        ("calibration.cube_power", {"m": 0.5}, r"calibration\.cube_power\.m: 0\.5 is less than the minimum of 1"),
    ],
)
def test_bad_values_name_key_and_reason(paper_config, path, value, message):
    _set(paper_config, path, value)
    with pytest.raises(ConfigError, match=message):
        validate_config(paper_config, source="config.yaml")


def test_observed_features_of_unknown_shot(paper_config):
    paper_config["observed"]["features"]["107S"] = dict(paper_config["observed"]["features"]["104S"])
    with pytest.raises(ConfigError, match=r"observed\.features\.107S: unknown shot"):
        validate_config(paper_config)


def test_missing_key_is_named(paper_config):
    del paper_config["shots"]["106S"]["flyer_mm"]
    with pytest.raises(ConfigError, match=r"shots\.106S: 'flyer_mm' is a required property"):
        validate_config(paper_config)


def test_unknown_shot_is_named(paper_config):
    with pytest.raises(ConfigError, match=r"unknown shot '107S'"):
        shot_config(paper_config, "107S")


def test_unquoted_shot_names_become_strings(tmp_path, paper_config):
    shots = paper_config["shots"]
    paper_config["shots"] = {104: shots["104S"]}
    paper_config["observed"]["features"] = {}
    paper_config["observed"]["records"] = {104: paper_config["observed"]["records"]["104S"]}
    paper_config["design"]["base_shots"] = [104]
    paper_config["next_shot"] = {"candidates": {"again": {"shot": 104, "flyer_mm": 3.95, "target_mm": 5.965,
                                                          "velocity_m_s": 204}}}
    validate_config(paper_config)
    assert list(paper_config["shots"]) == ["104"]
    assert list(paper_config["observed"]["records"]) == ["104"]
    assert paper_config["design"]["base_shots"] == ["104"]
    assert paper_config["next_shot"]["candidates"]["again"]["shot"] == "104"


@pytest.mark.parametrize("source, section", [("records", "records"), ("published", "features")])
def test_every_shot_needs_an_entry_for_the_observed_source(paper_config, source, section):
    paper_config["observed"]["source"] = source
    del paper_config["observed"][section]["105S"]
    with pytest.raises(ConfigError, match=rf"observed\.{section}\.105S: missing, and observed\.source is '{source}'"):
        validate_config(paper_config)


def test_unreadable_files(tmp_path):
    with pytest.raises(ConfigError, match="does not exist"):
        load_config(tmp_path / "missing.yaml")
    broken = tmp_path / "broken.yaml"
    broken.write_text("shots: [unclosed\n")
    with pytest.raises(ConfigError, match=f"{broken} is not valid YAML"):
        load_config(broken)


def test_the_library_validates_a_config_without_snakemake():
    """A notebook user needs neither snakemake installed nor imported: the schema check is jsonschema's."""
    code = ("import sys; from shockcal.study.validate import load_config; import shockcal.cli, shockcal.simulators.builtin; "
            "load_config('config/config.yaml'); print(sorted(m for m in sys.modules if m.startswith('snakemake')))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=REPO)
    assert out.stdout.strip() == "[]"


# every library settings dataclass a config section maps to (study/adapters.py): where its fields are read
# from (schema sections: `a.b` a sub-section, `*` a mapping's values, `#name` a schema definition), fields
# read from a key of another name, and whether the sections' defaults are all fields of it ("whole")
SETTINGS = [
    ("shockcal.hydro:HydroSettings", ["hydro"], {}, True),
    ("shockcal.hydro:Geometry", ["shots.*", "hydro"], {}, False),
    ("shockcal.hydro:MaterialProperties", ["material", "material.eos"], {}, False),
    ("shockcal.velocimetry.settings:ExtractorSettings", ["features", "shots.*.analysis"], {}, True),
    ("shockcal.emulator.settings:EmulatorSettings", ["emulator"], {"seed": "study.seed"}, False),
    ("shockcal.emulator.yield_input:YieldInput", ["emulator.yield_input"], {}, False),
    ("shockcal.inference.settings:SamplerSettings", ["calibration"], {"seed": "study.seed"}, False),
    ("shockcal.inference.settings:CheckSettings", ["calibration.check"], {}, True),
    ("shockcal.inference.settings:DiscrepancySettings", ["calibration.discrepancy"], {}, True),
    ("shockcal.inference.settings:CalibrationSettings", [],
     {"sd_fraction": "observed.sd_fraction", "check_units": "checks.observed_units",
      "check_plateau": "checks.plateau_vs_velocity", "check_training_range": "checks.features_in_training_range",
      "discrepancy": "calibration.discrepancy"}, False),
    ("shockcal.inference.settings:VerifySettings", ["verify"], {"discrepancy": "calibration.discrepancy"}, True),
    ("shockcal.design.settings:DesignSettings", ["design"], {}, False),
    ("shockcal.design.settings:NewShotSettings", ["design.new_shots"], {}, True),
    ("shockcal.design.settings:WaveSettings", ["design.waves"], {}, False),
    ("shockcal.inference.settings:StepSamplerSettings", ["design.waves.step_calibration"], {}, True),
    ("shockcal.plausibility:ChecksSettings", ["checks"], {}, True),
    ("shockcal.simulators.settings:SimulateSettings", ["simulate"], {}, True),
    ("shockcal.inference.settings:PredictSettings", ["predict"], {}, True),
    ("shockcal.campaign.settings:SensitivitySettings", ["sensitivity"], {}, True),
    ("shockcal.plots.settings:FigureSettings", ["figures"], {}, True),
    ("shockcal.campaign.settings:NextShotSettings", ["next_shot"], {}, False),
    ("shockcal.campaign.settings:ModulusSlopeSettings", ["next_shot.shear_modulus_log_slope_per_K"], {}, True),
    ("shockcal.campaign.settings:NextShotCheckSettings", ["next_shot.check"], {}, True),
    ("shockcal.velocimetry.settings:ObservedSettings", ["observed"], {}, False),
    ("shockcal.hydro.laws.settings:StrengthSettings", ["strength"], {}, False),
    ("shockcal.simulators.command:CommandSettings", ["simulator.command"], {}, False),
    ("shockcal.simulators.outputs:OutputSpec", ["#run_output"], {}, True),
    ("shockcal.campaign.candidates:Candidate", ["next_shot.candidates.*", "#candidate"], {}, False),
]


def _schema_node(schema: dict, path: str) -> dict:
    """The schema of the config key at dotted `path` (`*`: a mapping's values, `#name`: a definition)."""
    parts = path.split(".")
    node = schema["definitions"][parts.pop(0)[1:]] if parts[0].startswith("#") else schema
    for part in parts:
        node = _mapping_form(node)
        node = node["additionalProperties"] if part == "*" else node["properties"][part]
        if "$ref" in node:
            node = {**schema["definitions"][node["$ref"].rsplit("/", 1)[1]], **node}
    return node


def _section_node(schema: dict, path: str) -> dict:
    """The schema of the config section at dotted `path` (`_mapping_form`)."""
    return _mapping_form(_schema_node(schema, path))


def _mapping_form(node: dict) -> dict:
    """A key's schema; of a key that is a mapping or a word (`calibration.discrepancy`), its mapping form's."""
    return next(option for option in node["oneOf"] if option.get("type") == "object") if "oneOf" in node else node


def _field_names(cls) -> list[str]:
    """The fields of a settings dataclass or settings model (`shockcal.hydro.settings_model`)."""
    from dataclasses import fields

    return list(cls.model_fields) if hasattr(cls, "model_fields") else [f.name for f in fields(cls)]


def _library_defaults(cls) -> dict:
    """{field: default} of a dataclass's or settings model's fields that have one (a default_factory called)."""
    from dataclasses import MISSING, fields

    if hasattr(cls, "model_fields"):
        return {name: field.get_default(call_default_factory=True) for name, field in cls.model_fields.items()
                if not field.is_required()}
    return {f.name: f.default if f.default_factory is MISSING else f.default_factory()
            for f in fields(cls) if f.default is not MISSING or f.default_factory is not MISSING}


@pytest.mark.parametrize("target, sections, renamed, whole", SETTINGS, ids=[s[0].split(":")[1] for s in SETTINGS])
def test_library_settings_defaults_are_the_configs(target, sections, renamed, whole):
    """A notebook's `Settings()` and a config that leaves the keys out agree: a library default that differs
    from the schema's fails here, whichever side drifted."""
    import importlib

    from shockcal.study.config_files import load_schema

    module, name = target.split(":")
    cls = getattr(importlib.import_module(module), name)
    schema = load_schema()
    keys = {field: f"{section}.{field}" for section in reversed(sections) for field in _field_names(cls)
            if field in _section_node(schema, section).get("properties", {})} | renamed
    config = {field: _schema_node(schema, path) for field, path in keys.items()}
    config_defaults = {field: node["default"] for field, node in config.items() if "default" in node}
    library = _library_defaults(cls)
    assert config, f"{name}: no field is a config key (a section renamed?)"
    drift = {field: (library[field], default) for field, default in config_defaults.items()
             if field in library and library[field] != default}
    assert not drift, f"{name}: library default != config default: {drift}"
    required = {field for field, path in keys.items()
                if field in _section_node(schema, path.rsplit(".", 1)[0]).get("required", [])}
    unsaid = {field: library[field] for field in set(keys) - set(config_defaults) - required
              if library.get(field) is not None}      # the config leaves it out as "not given"
    assert not unsaid, f"{name}: a library default the config does not have: {unsaid}"
    if whole:   # the sections' every default is one of the settings', and every field a config key
        section_defaults = {k for section in sections
                            for k, node in _section_node(schema, section)["properties"].items() if "default" in node}
        assert section_defaults <= set(library) and set(library) <= set(keys)


@pytest.mark.parametrize("section", sorted(MODEL_SECTIONS))
def test_a_settings_models_section_of_the_schema_is_generated_from_it(section):
    """One definition: each field of the section's model is a schema key with the model's default (unless the
    section requires the key or the field is optional), description and rule, in its own section or the one it names (ExtractorSettings'
    analysis window: `shots.*.analysis`), and the YAML file names none of them."""
    from shockcal.settings_model import KEY, OPTIONAL, SECTION, other_sections, section_fields
    from shockcal.study.config_files import SCHEMA_PATH, load_schema, section_schema

    schema, model = load_schema(), MODEL_SECTIONS[section]
    for where in [section, *other_sections(model)]:
        written = section_schema(yaml.safe_load(SCHEMA_PATH.read_text()), where)["properties"]
        generated = section_fields(model, None if where == section else where)     # a KEY field is written there
        assert not set(generated) & set(written), f"{where}: a field of {model.__name__} also in the YAML"
    for name, field in model.model_fields.items():
        extra = field.json_schema_extra or {}
        node = section_schema(schema, extra.get(SECTION, section))
        if extra.get(KEY):       # e.g. the emulator's seed, study.seed: a key of the schema, not of this section
            assert name not in section_fields(model)
            assert (name in node["properties"]) == (extra[KEY] == f"{section}.{name}")   # a key of its own section
            assert ("default" in _schema_node(schema, extra[KEY])) != field.is_required()
            continue
        key = node["properties"][name]
        assert key["description"] == field.description and field.description
        assert key.get("x-rule") == extra.get("x-rule")
        assert key.get("x-unit") == extra.get("x-unit")
        if name in node.get("required", []) or extra.get(OPTIONAL):     # required, or left out: not given
            assert "default" not in key
        else:
            assert key["default"] == field.default


@pytest.mark.parametrize("path, value, message", [
    ("next_shot.candidates", [{"shot": "104S", "flyer_mm": 3.95, "target_mm": 5.965, "velocity_m_s": 204}],
     "next_shot.candidates: a list given, but it must be a mapping (key: value) or null"),
    ("shots", [{"flyer_mm": 3.95, "target_mm": 5.965}], "shots: a list given, but it must be a mapping (key: value)"),
    ("observed", "records", "observed: 'records' is not of type 'object'"),
])
def test_a_config_of_the_wrong_shape_gets_the_schemas_line(paper_config, path, value, message):
    """The schema speaks before any code that assumes the config's shape (no AttributeError)."""
    _set(paper_config, path, value)
    with pytest.raises(ConfigError) as err:
        validate_config(paper_config, source="config.yaml")
    assert str(err.value) == f"config.yaml: {message}"


@pytest.mark.parametrize("path, typo, message", [
    ("shots.104S", "traget_mm", "shots.104S: Additional properties are not allowed ('traget_mm' was unexpected); "
                                "did you mean 'target_mm'?"),
    ("hydro", "cell_size", "hydro: Additional properties are not allowed ('cell_size' was unexpected); "
                           "did you mean 'cell_size_um'?"),
    ("", "shot", "<top level>: Additional properties are not allowed ('shot' was unexpected); did you mean 'shots'?"),
])
def test_a_key_typo_gets_did_you_mean(paper_config, path, typo, message):
    _set(paper_config, f"{path}.{typo}".lstrip("."), 1.0)
    with pytest.raises(ConfigError) as err:
        validate_config(paper_config, source="config.yaml")
    assert str(err.value) == f"config.yaml: {message}"


def test_an_error_names_the_file_of_the_merged_config_that_sets_the_key(tmp_path, monkeypatch):
    """Snakemake merges config/config.yaml, then each --configfile overlay, then --config; the message
    names the one that set the key at fault (tests/test_faults.py runs snakemake on an overlay)."""
    from shockcal.study.validate import config_source_of

    monkeypatch.chdir(REPO)
    overlay = tmp_path / "overlay.yaml"
    overlay.write_text("simulate:\n  chunk_size: 0\nshots:\n  104S:\n    flyer_mm: 0.001\n")
    files = ["config/config.yaml", "config/quick.yaml", str(overlay)]
    assert config_source_of("simulate.chunk_size", files) == str(overlay)
    assert config_source_of("shots.104S.flyer_mm", files) == str(overlay)
    assert config_source_of("shots.104S.target_mm", files) == "config/config.yaml"
    assert config_source_of("hydro.cell_size_um", files) == "config/quick.yaml"
    assert config_source_of("hydro.cfl", files, {"hydro": {"cfl": 2}}) == "snakemake --config"
