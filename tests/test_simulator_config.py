"""The `simulator` section: bad configs refused in one line naming the key, before any run starts."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest
import yaml

from shockcal.cli import main
from shockcal.errors import ConfigError
from shockcal.study.adapters import study_design
from shockcal.study.stages import stage_config
from shockcal.study.validate import validate_config

REPO = Path(__file__).resolve().parents[1]
DECK = REPO / "examples" / "external_hydro" / "deck.txt"
TRACE = {"kind": "trace", "file": "trace.csv", "time_column": "t_us", "velocity_column": "v_m_s"}


def command_section(**changes) -> dict:
    section = {"templates": [str(DECK)], "command": "{python} run.py deck.txt", "timeout_s": 10, "output": dict(TRACE)}
    return {"kind": "command", "command": {**section, **changes}}


def test_the_example_deck_is_valid_and_builtin_is_the_default(paper_config):
    assert "simulator" not in validate_config(paper_config)      # left out: builtin, and no simulate job reruns
    paper_config["simulator"] = command_section()
    validate_config(paper_config)
    assert "simulator" in stage_config(paper_config, "simulate", "104S")


@pytest.mark.parametrize("changes, message", [
    ({"templates": ["no/such/deck.txt"]}, r"simulator\.command\.templates\[0\]: no/such/deck\.txt does not exist"),
    ({"command": "{python} run.py --velocity {velocity}"},
     r"simulator\.command\.command: line 1: unknown placeholder \{velocity\}; known: run \(id\)"),
    ({"timeout_s": 0}, r"simulator\.command\.timeout_s: 0 is not a positive number"),
    ({"output": {"kind": "trace", "file": "trace.csv", "time_column": "t_us"}},
     r"simulator\.command\.output\.velocity_column: missing; a trace output names its velocity column"),
    ({"retries": -1}, r"simulator\.command\.retries: -1 is less than the minimum of 0"),
])
def test_bad_command_sections_name_the_key(paper_config, changes, message):
    paper_config["simulator"] = command_section(**changes)
    with pytest.raises(ConfigError, match=message) as err:
        validate_config(paper_config, source="config.yaml")
    assert "\n" not in str(err.value)


def test_an_unknown_placeholder_in_a_template_names_file_and_line(paper_config, tmp_path):
    deck = tmp_path / "deck.txt"
    deck.write_text("# my code's deck\nyield = {A_MPa}\nspeed = {velocity_km_s:.4f}\n")
    paper_config["simulator"] = command_section(templates=[str(deck)])
    with pytest.raises(ConfigError, match=r"templates\[0\] \(.*deck\.txt\): line 3: unknown placeholder "
                                          r"\{velocity_km_s\}"):
        validate_config(paper_config)


@pytest.fixture
def archive(paper_config, tmp_path):
    """A six-run archive: a design and each shot's features (values plausible; they are not read here)."""
    from shockcal.design.tables import latin_hypercube
    from shockcal.study.config import prior_bounds

    latin_hypercube(prior_bounds(paper_config), 6, seed=4).to_csv(tmp_path / "design.csv", index=False)
    row = paper_config["observed"]["features"]["104S"]
    for shot in paper_config["shots"]:
        pd.DataFrame([{"run": run, **row} for run in range(6)]).to_csv(tmp_path / f"{shot}.csv", index=False)
    paper_config["simulator"] = {"kind": "archive", "archive": {
        "design": str(tmp_path / "design.csv"),
        "features": {shot: str(tmp_path / f"{shot}.csv") for shot in paper_config["shots"]}}}
    return paper_config, tmp_path


def test_an_archive_is_the_training_design(archive):
    config, folder = archive
    validate_config(config)
    design, source = study_design(config)
    assert design["run"].tolist() == list(range(6)) and source.startswith("archive ")


def test_an_archive_whose_features_hold_runs_the_design_lacks_is_refused(archive):
    config, folder = archive
    table = pd.read_csv(folder / "105S.csv")
    table.loc[5, "run"] = 17
    table.to_csv(folder / "105S.csv", index=False)
    with pytest.raises(ConfigError, match=r"simulator\.archive\.features\.105S: runs \[17\] \(1 in all\) are not in "
                                          r"simulator\.archive\.design .* disagree in their run ids") as err:
        validate_config(config)
    assert "\n" not in str(err.value)


def test_reference_data_is_the_configs_folder_unless_the_environment_names_one(archive, monkeypatch, tmp_path):
    """{reference_data} stands for simulator.archive.reference_data, $SHOCKCAL_REFERENCE_DATA overriding it
    (no folder is built into the code); neither, or a folder that is not there, is one line naming the key."""
    config, folder = archive
    archive_section = config["simulator"]["archive"]
    archive_section.update(design="{reference_data}/design.csv",
                           features={shot: f"{{reference_data}}/{shot}.csv" for shot in config["shots"]})
    monkeypatch.delenv("SHOCKCAL_REFERENCE_DATA", raising=False)
    with pytest.raises(ConfigError, match=r"simulator\.archive\.design: \{reference_data\}/design\.csv: "
                                          r"\{reference_data\} names no folder") as err:
        validate_config(dict(config, simulator={"kind": "archive", "archive": dict(archive_section)}))
    assert "\n" not in str(err.value)
    archive_section["reference_data"] = str(tmp_path / "elsewhere")
    with pytest.raises(ConfigError, match=r"folder .*elsewhere does not exist here"):
        validate_config(dict(config, simulator={"kind": "archive", "archive": dict(archive_section)}))
    monkeypatch.setenv("SHOCKCAL_REFERENCE_DATA", str(folder))
    assert study_design(validate_config(config))[0]["run"].tolist() == list(range(6))
    monkeypatch.delenv("SHOCKCAL_REFERENCE_DATA")
    archive_section["reference_data"] = str(folder)
    assert study_design(validate_config(config))[0]["run"].tolist() == list(range(6))


def test_an_archive_whose_shots_hold_other_runs_is_refused(archive):
    config, folder = archive
    pd.read_csv(folder / "106S.csv").iloc[:4].to_csv(folder / "106S.csv", index=False)
    with pytest.raises(ConfigError, match=r"features\.106S: its run ids differ from simulator\.archive\.features\.104S"):
        validate_config(config)


def test_the_cli_refuses_a_bad_simulator_in_one_line_before_running(paper_config, tmp_path, capsys):
    paper_config["simulator"] = command_section(timeout_s=0)
    config = tmp_path / "config.yaml"
    config.write_text(yaml.safe_dump(paper_config))
    code = main(["simulate", "--config", str(config), "--shot", "104S", "--design", "unused.csv",
                 "--out", str(tmp_path / "out.parquet")])
    err = capsys.readouterr().err.strip()
    assert code == 2 and err.count("\n") == 0 and "simulator.command.timeout_s" in err
    assert not (tmp_path / "runs").exists()


def test_the_library_refuses_what_the_config_refuses():
    from shockcal.errors import InputError
    from shockcal.simulators.command import CommandSettings
    from shockcal.simulators.outputs import OutputSpec

    with pytest.raises(InputError, match=r"OutputSpec\.velocity_column: missing; a trace output names its velocity"):
        OutputSpec(kind="trace", file="trace.csv", time_column="t")
    with pytest.raises(InputError, match=r"OutputSpec\.velocity_column '': String should have at least 1 character"):
        OutputSpec(kind="trace", file="trace.csv", time_column="t", velocity_column="")
    with pytest.raises(InputError, match=r"OutputSpec\.velocity_unit 'm/us': Input should be 'cm/us', 'm/s'"):
        OutputSpec(kind="trace", file="trace.csv", time_column="t", velocity_column="v", velocity_unit="m/us")
    with pytest.raises(InputError, match=r"CommandSettings\.timeout_s: 0 is not a positive number"):
        CommandSettings(templates=["deck.txt"], command="run", output=OutputSpec(kind="features", file="features.csv"),
                        timeout_s=0)
