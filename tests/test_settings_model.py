"""The settings models that are config sections (`shockcal.settings_model`): the emulator's and the extractor's
settings refuse on construction what the config refuses, each door naming the key, and the config reaches
them by name; a model section's keys keep their order in a validated config."""

from __future__ import annotations

import pytest

from shockcal.emulator.settings import EmulatorSettings
from shockcal.errors import ConfigError, InputError
from shockcal.settings_model import section_fields
from shockcal.study.adapters import emulator_settings, extractor_settings
from shockcal.study.config_files import _placed
from shockcal.study.validate import validate_config
from shockcal.velocimetry.settings import ExtractorSettings


@pytest.mark.parametrize("key, value", [
    ("n_components", 0), ("n_components", -0.5), ("n_starts", 0), ("max_fit_runs", 9), ("n_jobs", 0),
    ("cv_folds", 1), ("switch_ratio", -0.1), ("family", "rbf"), ("sd_model", "linear"), ("error_tails", "cauchy"),
    ("n_starts", "two"), ("fit_mean", [True]), ("n_start", 2), ("n_starts", "2"), ("fit_mean", "yes"),
    ("fit_mean", 1), ("switch_ratio", True), ("n_components", None),
])
def test_both_doors_refuse_a_bad_emulator_setting_naming_it(paper_config, key, value):
    paper_config["emulator"][key] = value
    with pytest.raises(ConfigError, match=rf"^config\.yaml: emulator(\.{key})?: "):
        validate_config(paper_config, source="config.yaml")
    with pytest.raises(InputError, match=rf"^EmulatorSettings\.{key} .*: [^\n]+$"):
        EmulatorSettings(**{key: value})


@pytest.mark.parametrize("key, value", [
    ("n_components", 5), ("n_components", 0.9), ("n_starts", 1), ("max_fit_runs", 10), ("n_jobs", 1),
    ("cv_folds", 2), ("switch_ratio", 0.0), ("family", "gaussian"), ("sd_model", "constant"),
    ("error_tails", "gaussian"), ("fit_mean", False), ("calibrate_sd", False), ("cv_warm_start", False),
])
def test_a_setting_the_config_accepts_reaches_the_library_by_name(paper_config, key, value):
    paper_config["emulator"][key] = value
    paper_config["study"]["seed"] = 7
    config = validate_config(paper_config)
    settings = emulator_settings(config)
    assert getattr(settings, key) == value and type(getattr(settings, key)) is type(value)
    assert settings.seed == 7
    assert all(getattr(settings, name) == config["emulator"][name] for name in section_fields(EmulatorSettings))


def test_an_unknown_setting_gets_the_closest_name_through_both_doors(paper_config):
    paper_config["emulator"]["n_start"] = 2
    with pytest.raises(ConfigError, match="did you mean 'n_starts'"):
        validate_config(paper_config)
    with pytest.raises(InputError, match=r"^EmulatorSettings\.n_start 2: .*; did you mean 'n_starts'\?$"):
        EmulatorSettings(n_start=2)


def test_the_settings_are_frozen_and_a_changed_copy_is_checked():
    settings = EmulatorSettings(n_starts=3)
    with pytest.raises(ValueError):
        settings.n_starts = 4
    assert settings.replace(n_starts=4).n_starts == 4 and settings.n_starts == 3
    with pytest.raises(InputError, match=r"^EmulatorSettings\.cv_folds 1: "):
        settings.replace(cv_folds=1)


def test_a_model_sections_yaml_keys_are_placed_after_their_x_after():
    """The order defaults are filled in (the workflow's rerun triggers compare a stage's slice as written)."""
    generated = {"a": {}, "b": {}, "c": {}}
    written = {"first": {}, "after_b": {"x-after": "b"}, "next": {}, "last": {"x-after": "c"}}
    assert list(_placed(generated, written)) == ["first", "a", "b", "after_b", "next", "c", "last"]


def test_the_emulator_sections_keys_keep_their_order(paper_config):
    """A config that leaves emulator keys out gets them in the schema's order: the order before the section was
    generated from EmulatorSettings (2026-11-29), so no study's emulate jobs rerun for it."""
    paper_config["emulator"] = {}
    assert list(validate_config(paper_config)["emulator"]) == [
        "structure", "n_components", "n_starts", "max_fit_runs", "family", "fit_mean", "hardening_strain",
        "homologous_temperature", "yield_input", "n_jobs", "cv_folds", "calibrate_sd", "cv_warm_start",
        "switch_ratio", "sd_model", "error_tails", "outer_margin"]


@pytest.mark.parametrize("section, key, value", [
    ("shots.104S.analysis", "window_after_arrival_us", 0.0), ("shots.104S.analysis", "cutoff_after_arrival_us", -0.01),
    ("features", "n_components", 1), ("features", "n_samples", 99), ("features", "n_samples", 1e4 + 0.5),
    ("shots.104S.analysis", "window_after_arrival_us", "1.2 us"),
])
def test_both_doors_refuse_a_bad_extractor_setting_naming_it(paper_config, section, key, value):
    node = paper_config
    for part in section.split("."):
        node = node[part]
    node[key] = value
    with pytest.raises(ConfigError, match=rf"^config\.yaml: {section.replace('.', r'[.]')}\.{key}: "):
        validate_config(paper_config, source="config.yaml")
    with pytest.raises(InputError, match=rf"^ExtractorSettings\.{key} .*: [^\n]+$"):
        ExtractorSettings(**{key: value})


def test_the_extractor_reads_its_shots_window_and_the_studys_mixture(paper_config):
    """Two config sections, one library setting: the shot's `analysis` and the study's `features`."""
    paper_config["shots"]["105S"]["analysis"] = {"window_after_arrival_us": 0.9}
    paper_config["features"] = {"n_samples": 2000}
    config = validate_config(paper_config)
    assert extractor_settings(config, "105S") == ExtractorSettings(window_after_arrival_us=0.9, n_samples=2000)
    assert extractor_settings(config, "104S").window_after_arrival_us == config["shots"]["104S"]["analysis"][
        "window_after_arrival_us"]


@pytest.mark.parametrize("key, value", [("cfl", "0.5"), ("cell_size_um", True)])
def test_a_hydro_setting_of_the_wrong_type_is_refused_by_both_doors(paper_config, key, value):
    from shockcal.hydro import HydroSettings

    paper_config["hydro"][key] = value
    with pytest.raises(ConfigError, match=rf"^config\.yaml: hydro\.{key}: "):
        validate_config(paper_config, source="config.yaml")
    with pytest.raises(InputError, match=rf"^HydroSettings\.{key} .*: not a number$"):
        HydroSettings(**{key: value})
