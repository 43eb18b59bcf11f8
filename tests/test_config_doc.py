"""docs/configuration.md is the schema's page: every key described, the page regenerated, reruns from STAGE_KEYS."""

import copy
from pathlib import Path

import pytest

from shockcal.cli import main
from shockcal.errors import ConfigError
from shockcal.study.config_doc import DOC_PATH, load_schema, render, reruns, schema_keys, undescribed

REPO = Path(__file__).resolve().parents[1]


def property_schemas(node, where=""):
    """Every property schema of a raw schema (definitions and free-form mappings included), by where it is."""
    if isinstance(node, dict):
        for name, sub in node.get("properties", {}).items():
            yield f"{where}.{name}", sub
        if isinstance(node.get("additionalProperties"), dict):
            yield f"{where}.*", node["additionalProperties"]
        for key, sub in node.items():
            yield from property_schemas(sub, f"{where}.{key}")
    elif isinstance(node, list):
        for i, sub in enumerate(node):
            yield from property_schemas(sub, f"{where}[{i}]")


def test_every_schema_property_has_a_description():
    schema = load_schema()
    missing = [where for where, sub in property_schemas(schema) if not str(sub.get("description", "")).strip()]
    assert not missing, f"properties without a description: {missing}"
    assert undescribed(schema) == []
    assert len(schema_keys(schema)) > 100


def test_committed_page_is_the_generated_one():
    """Regenerate with `shockcal config-doc --out docs/configuration.md` after editing the schema."""
    assert (REPO / DOC_PATH).read_text() == render(), "docs/configuration.md is stale: run shockcal config-doc"


def test_page_has_a_row_per_key():
    page = render()
    for key in schema_keys(load_schema()):
        if len(key.path) > 1:
            assert f"| `{key.name}` |" in page, key.name
    assert "| `hydro.end_time_us` | number or string | *required* | us | > 0 or one of `auto`, `per_run` |" in page
    assert "| `figures.formats` | list of string | `[png, pdf]` |  | each one of `png`, `pdf`, `svg` |" in page


def test_schema_with_descriptions_still_validates_configs():
    """`description` and `x-unit` are annotations: the schema is valid 2020-12, and configs validate as before."""
    from jsonschema import Draft202012Validator

    from shockcal.study.validate import load_config

    Draft202012Validator.check_schema(load_schema())
    config = load_config(REPO / "config" / "config.yaml")
    assert config["hydro"]["end_time_us"] == "auto" and config["study"]["results_dir"] == "results"


def test_reruns_come_from_the_stage_declarations():
    assert reruns(("hydro", "cfl")) == "simulate; next_shot_simulate"        # the next-shot candidates' runs too
    assert reruns(("simulate", "chunk_size")) == "*none declared*"
    assert reruns(("calibration", "n_live")) == "calibrate"
    assert reruns(("shots", "<shot>", "analysis", "cutoff_after_arrival_us")).startswith(
        "features (its shot); failure_budget (its shot); observed; next_shot_design; next_shot_simulate; "
        "next_shot_features; next_shot_check_truths; figures ")
    assert "simulate (shots that read it)" in reruns(("inputs", "<input>", "min"))
    assert reruns(("observed", "sd_fraction")) == ("calibrate; calibrate_check; wave_design; verify; suggest_shot; "
                                                   "figures 9, 10, features_vs_training")
    assert reruns(("figures", "dpi")) == "figures"
    # a toy declaration: prefixes either way, wildcards, the job's shot
    stages = {"a": ("x.y",), "b": ("x",), "c": ("x.{shot}.z",), "d": ("w",)}
    assert reruns(("x",), stages, {}) == "a; b; c (its shot)"
    assert reruns(("x", "y", "q"), stages, {}) == "a; b"          # c reads x.<shot>.z only
    assert reruns(("x", "v"), stages, {"fig01_a": ("x.v",), "fig02_b": ("x",), "fig03_c": ("w",)}) == \
        "b; c (its shot); figures 1, 2"


def test_a_property_without_description_is_refused():
    schema = copy.deepcopy(load_schema())
    del schema["properties"]["hydro"]["properties"]["cfl"]["description"]
    with pytest.raises(ConfigError, match="hydro.cfl has no description"):
        render(schema)
    schema = copy.deepcopy(load_schema())
    schema["properties"]["figures"]["properties"]["extra"] = {"type": "object", "description": "x",
                                                               "additionalProperties": {"type": "number"}}
    with pytest.raises(ConfigError, match="figures.extra holds free-form keys"):
        render(schema)


def test_cli_writes_and_checks_the_page(tmp_path, capsys):
    out = tmp_path / "configuration.md"
    assert main(["config-doc", "--out", str(out)]) == 0
    assert out.read_text() == render()
    assert main(["config-doc", "--out", str(out), "--check"]) == 0
    out.write_text(out.read_text().replace("Largest time step.", "The largest step."))
    assert main(["config-doc", "--out", str(out), "--check"]) == 2
    assert "is not the schema's page" in capsys.readouterr().err
    assert main(["config-doc"]) == 0 and capsys.readouterr().out == render()


def test_page_units_match_the_key_names():
    """A key whose name carries a unit shows it; the schema's x-unit only where the name has none."""
    schema = load_schema()
    for key in schema_keys(schema):
        if "x-unit" in key.schema:
            assert not any(key.path[-1].endswith(s) for s in ("_us", "_ns", "_mm", "_um", "_K", "_Mbar")), key.name
