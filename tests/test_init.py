"""`shockcal init DIR`: a commented starting config with every schema key, its placeholders refused in one
line until filled, a valid study once they are; an existing config is never overwritten."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
import yaml

from shockcal.cli import main
from shockcal.errors import ConfigError
from shockcal.study.config_doc import load_schema, schema_keys
from shockcal.study.config_files import FILL_IN
from shockcal.study.config_template import FILLED_MAPPINGS, render_template
from shockcal.study.validate import load_config

REPO = Path(__file__).resolve().parents[1]
EXAMPLE = REPO / "examples" / "copper" / "config.yaml"
# the sections the worked example's edit fills in (docs/your_material.md; its material is init's --material)
EDITED = ("material", "hydro", "shots", "inputs")


def init(folder: Path, *options: str) -> Path:
    assert main(["init", str(folder), *options]) == 0
    return folder / "config.yaml"


def test_every_schema_key_is_written_with_its_default(tmp_path):
    text = init(tmp_path / "copper").read_text()
    lines = text.splitlines()
    shown = 0
    for key in schema_keys(load_schema()):
        inside = [".".join(key.path[:i]) for i, part in enumerate(key.path) if part.startswith("<")]
        if any(mapping not in FILLED_MAPPINGS or mapping == "inputs" for mapping in inside) or "[]" in key.name:
            continue                      # a free-form mapping's or a list's entries: only shots' and records' are shown
        indent = "  " * (len(key.path) - 1)
        pattern = re.compile(rf"^{indent}(# )?{re.escape(key.path[-1])}:( |$)")
        written = [line for line in lines if pattern.match(line)]
        assert written, key.name
        if "default" in key.schema and "properties" not in key.schema and key.name not in FILLED_MAPPINGS \
                and key.path[0] != "study":
            assert any(yaml.safe_load(line.split(":", 1)[1].split("   #")[0] or "null") == key.schema["default"]
                       for line in written), key.name
        shown += 1
    assert shown > 150


def test_the_unfilled_config_is_refused_in_one_line_naming_the_key(tmp_path):
    path = init(tmp_path / "copper")
    with pytest.raises(ConfigError) as refused:
        load_config(path)
    assert str(refused.value) == f"{path}: material.rho0_g_cc: still {FILL_IN} (from `shockcal init`); give its value"


def filled(path: Path, records: Path) -> dict:
    """The init config with the worked example's edit: its sections from examples/copper/config.yaml, the
    records in `records` (files that exist)."""
    config = yaml.safe_load(path.read_text())
    example = yaml.safe_load(EXAMPLE.read_text())
    for section in EDITED:
        config[section] = example[section]
    config["observed"]["records"] = {}
    for shot in example["shots"]:
        (records / f"{shot}.txt").parent.mkdir(parents=True, exist_ok=True)
        (records / f"{shot}.txt").write_text("a record\n")
        config["observed"]["records"][shot] = {"path": str(records / f"{shot}.txt")}
    return config


def test_the_config_validates_once_its_placeholders_are_filled(tmp_path):
    path = init(tmp_path / "copper")
    path.write_text(yaml.safe_dump(filled(path, tmp_path / "records")))
    config = load_config(path)
    assert {k: config["study"][k] for k in ("name", "seed", "results_dir")} == {"name": "copper", "seed": 0,
                                                                               "results_dir": "results/copper"}
    assert list(config["shots"]) == ["Cu300", "Cu500"] and config["calibration"]["cube_power"] == {}


def test_a_placeholder_name_left_is_refused(tmp_path):
    path = init(tmp_path / "copper")
    config = filled(path, tmp_path / "records")
    config["shots"]["<shot>"] = config["shots"].pop("Cu500")
    path.write_text(yaml.safe_dump(config))
    with pytest.raises(ConfigError, match=r"shots\.<shot>: a placeholder name from `shockcal init`"):
        load_config(path)


def settings(lines: list[str]) -> list[str]:
    """A config's key lines, comments (its own lines and inline ones) left out."""
    return [line.split("   #")[0] for line in lines if line.strip() and not line.lstrip().startswith("#")]


def test_the_example_is_the_template_with_only_placeholder_lines_edited():
    """examples/copper/config.yaml is `shockcal init`'s output with the edit docs/your_material.md counts:
    every setting it changes held a placeholder (or is a shot's analysis window); it adds the second shot's,
    its record's and its velocity input's lines."""
    import difflib

    template = settings(render_template("studies/copper/config.yaml", "copper", "copper").splitlines())
    example = settings(EXAMPLE.read_text().splitlines())
    diff = list(difflib.ndiff(template, example))
    removed = [line for line in diff if line.startswith("- ")]
    added = [line for line in diff if line.startswith("+ ")]
    assert removed and all(FILL_IN in line or "<shot>" in line or "window_after_arrival_us" in line for line in removed)
    assert len(added) == len(removed) + 3


def test_a_library_material_is_named_and_its_values_shown(tmp_path, capsys):
    path = init(tmp_path / "copper", "--material", "copper")
    text = path.read_text()
    assert "\n  name: copper\n" in text and "\n  # rho0_g_cc: 8.93   #" in text and "\n    # s: 1.489   #" in text
    assert yaml.safe_load(text)["material"] == {"name": "copper"}
    assert main(["init", str(tmp_path / "other"), "--material", "coper"]) == 2
    assert capsys.readouterr().err.strip().endswith("--material: unknown material 'coper'; the library has al5083, "
                                                    "copper, tantalum, ti6al4v")
    assert not (tmp_path / "other").exists()


def test_init_never_overwrites(tmp_path, capsys):
    path = init(tmp_path / "copper")
    path.write_text("mine\n")
    assert main(["init", str(tmp_path / "copper")]) == 2
    assert path.read_text() == "mine\n"
    assert capsys.readouterr().err.strip().endswith("exists; init writes a new study's config only (choose another "
                                                    "folder, or edit it)")
