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


@pytest.mark.parametrize("section, key, value, model", [
    ("calibration", "n_live", 49, "SamplerSettings"), ("calibration", "n_eff", 99, "SamplerSettings"),
    ("calibration", "draws", 0, "SamplerSettings"), ("calibration", "replicates", 2, "SamplerSettings"),
    ("calibration", "replicates", 0, "SamplerSettings"), ("calibration", "max_evaluations", 999, "SamplerSettings"),
    ("calibration", "n_live", "500", "SamplerSettings"), ("calibration", "n_live", 500.5, "SamplerSettings"),
    ("calibration", "cube_power", {"m": 0.5}, "SamplerSettings"), ("calibration", "cube_power", {"m": 11},
                                                                    "SamplerSettings"),
    ("calibration", "cube_power", {"m": "2"}, "SamplerSettings"), ("calibration", "n_lives", 500, "SamplerSettings"),
    ("calibration.check", "trials", 0, "CheckSettings"), ("calibration.check", "trials_per_job", 0, "CheckSettings"),
    ("calibration.check", "n_live", 10, "CheckSettings"), ("calibration.check", "n_eff", 50, "CheckSettings"),
    ("calibration.discrepancy", "sd_fraction_prior", 0.8, "DiscrepancySettings"),
    ("calibration.discrepancy", "sd_fraction_prior", 0, "DiscrepancySettings"),
    ("calibration.discrepancy", "kind", "gp", "DiscrepancySettings"),
    ("calibration.discrepancy", "rho", 0.5, "DiscrepancySettings"),
])
def test_both_doors_refuse_a_bad_calibration_setting_naming_it(paper_config, section, key, value, model):
    """The sampler's, the check's and the discrepancy's settings: the config names the key (a mapping's key too),
    the library the model and the field."""
    import shockcal.inference.settings as settings

    *parents, last = section.split(".")
    node = paper_config
    for part in parents:
        node = node[part]
    if last == "discrepancy":
        node[last] = {"kind": "feature_kind"}
    node[last][key] = value
    with pytest.raises(ConfigError, match=rf"^config\.yaml: {section.replace('.', r'[.]')}(\.{key})?[.:]"):
        validate_config(paper_config, source="config.yaml")
    values = {"kind": "feature_kind", key: value} if last == "discrepancy" else {key: value}
    with pytest.raises(InputError, match=rf"^{model}\.{key}[. ].*: [^\n]+$"):
        getattr(settings, model)(**values)


def test_replicates_2_is_refused_in_the_models_words_at_both_doors(paper_config):
    """A rule the schema cannot say (`check_model_sections`): the config's line is the model's reason."""
    from shockcal.inference.settings import SamplerSettings

    paper_config["calibration"]["replicates"] = 2
    with pytest.raises(ConfigError) as config_door:
        validate_config(paper_config, source="config.yaml")
    with pytest.raises(InputError) as library_door:
        SamplerSettings(replicates=2)
    assert str(config_door.value) == f"config.yaml: calibration.replicates: {library_door.value.reason}"
    assert str(library_door.value).startswith("SamplerSettings.replicates 2: 2 runs give no usable spread")


def test_the_calibration_settings_the_config_accepts_reach_the_library_by_name(paper_config):
    from shockcal.inference.settings import CheckSettings, DiscrepancySettings, SamplerSettings
    from shockcal.study.adapters import calibration_settings

    paper_config["calibration"].update(n_live=300, n_eff=900, draws=123, replicates=3, cube_power={"m": 2.5},
                                       max_evaluations=4000, discrepancy={"kind": "feature_kind"},
                                       check={"n_live": 60, "n_eff": 150})
    config = validate_config(paper_config)
    settings = calibration_settings(config, ["104S"])
    assert all(getattr(settings.sampler, name) == config["calibration"][name] for name in section_fields(SamplerSettings))
    assert (settings.sampler.n_live, settings.sampler.replicates, settings.sampler.cube_power) == (300, 3, {"m": 2.5})
    assert settings.discrepancy == DiscrepancySettings(kind="feature_kind", sd_fraction_prior=0.02)
    assert settings.sd_fraction == config["observed"]["sd_fraction"]
    trial = calibration_settings(config, ["104S"], check=True).sampler
    assert (trial.n_live, trial.n_eff, trial.draws, trial.replicates) == (60, 150, 150, 1)
    assert (trial.cube_power, trial.max_evaluations, trial.seed) == ({"m": 2.5}, 4000, settings.sampler.seed)
    assert CheckSettings(**config["calibration"]["check"]).trials == 100


def test_the_calibration_sections_keys_keep_their_order(paper_config):
    """The order before the section was generated from SamplerSettings (2026-11-29): no calibrate job reruns."""
    paper_config["calibration"] = {}
    calibration = validate_config(paper_config)["calibration"]
    assert list(calibration) == ["discrepancy", "n_live", "n_eff", "draws", "replicates", "cube_power",
                                 "max_evaluations", "check"]
    assert list(calibration["check"]) == ["trials", "trials_per_job", "n_live", "n_eff"]


def test_a_calibration_setting_is_frozen_and_its_changed_copy_checked():
    from shockcal.inference.settings import CalibrationSettings

    settings = CalibrationSettings()
    with pytest.raises(ValueError):
        settings.sd_fraction = 0.02
    assert settings.with_sampler(n_eff=200).sampler.n_eff == 200 and settings.sampler.n_eff == 3000
    with pytest.raises(InputError, match=r"^SamplerSettings\.n_eff 20: "):
        settings.with_sampler(n_eff=20)
    with pytest.raises(InputError, match=r"^DiscrepancySettings\.sd_fraction_prior 0\.8: "):
        settings.replace(discrepancy={"kind": "feature_kind", "sd_fraction_prior": 0.8})
