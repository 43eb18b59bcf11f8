"""shockcal.study.stages: one declaration of the config keys each stage reads, serving both the rules'
params and the slice each command hands its library code."""
from pathlib import Path

import pytest

from shockcal.study.figure_catalogue import catalogue
from shockcal.study.stages import STAGE_KEYS, config_slice, figure_config, stage_config
from shockcal.study.validate import load_config

REPO = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def config():
    return load_config(REPO / "config" / "config.yaml")


def needs_shot(stage: str) -> bool:
    return any("{shot" in path for path in STAGE_KEYS[stage])


def subjects(config, stage: str) -> list:
    """What a stage's `{shot}` names: a shot, or for the next-shot stages a candidate (None: no shot)."""
    if not needs_shot(stage):
        return [None]
    return list(config["next_shot"]["candidates"] if stage.startswith("next_shot") else config["shots"])


def test_every_declared_key_exists_in_the_default_study(config):
    for stage in STAGE_KEYS:
        for shot in subjects(config, stage):
            assert stage_config(config, stage, shot), stage
    for name in catalogue(config):
        assert "figures" in figure_config(config, name)


def test_a_shot_stage_sees_its_own_shot_and_inputs_only(config):
    sliced = stage_config(config, "simulate", "105S")
    assert list(sliced["shots"]) == ["105S"]
    assert set(sliced["inputs"]) == {"A", "B", "C", "n", "m", "V2", "G1", "Delta2"}
    assert "analysis" in sliced["shots"]["105S"] and set(sliced["shots"]["105S"]["analysis"]) == {
        "window_after_arrival_us"}
    assert not {"emulator", "calibration", "observed", "features", "study"} & set(sliced)


def test_a_sampler_setting_is_outside_every_stage_but_the_calibration(config):
    readers = {stage for stage in STAGE_KEYS
               if "n_live" in stage_config(config, stage, subjects(config, stage)[0]).get("calibration", {})}
    assert readers == {"calibrate"}


def test_a_models_keys_are_its_fields_and_the_sections_they_name():
    """`model_keys`: each field once, in order, as its section's key; a field of another section by that section;
    an optional field marked (sliced only when given) or left out; a field given by a key of its own not at all."""
    from shockcal.settings_model import SettingsModel, setting
    from shockcal.study.stages import model_keys

    class Toy(SettingsModel):
        first: float = setting(1.0, "a key of the section")
        a: float = setting(1.0, "a key of the section's sub-section", section="toy.sub")
        b: float = setting(1.0, "the same sub-section", section="toy.sub")
        maybe: float | None = setting(None, "left out: not given", optional=True)
        seed: int = setting(0, "a key of its own", key="study.seed")

    assert model_keys(Toy, "toy") == ("toy.first", "toy.sub", "toy.maybe?")
    assert model_keys(Toy, "toy", optional=False) == ("toy.first", "toy.sub")


def test_the_simulate_stage_reads_every_plate_and_material_key(config):
    """What the hydrocode takes, Plates and MaterialProperties, is in the simulate slice, field by field: a field
    either model gains reruns the simulations without a line in stages.py (the law-specific material constants,
    optional, only for a law that reads them)."""
    from shockcal.hydro.settings import MaterialProperties, Plates
    from shockcal.settings_model import OPTIONAL, SECTION, schema_extras

    sliced = stage_config(config, "simulate", "104S")
    assert {name for name in Plates.model_fields if name in config["shots"]["104S"]} <= set(sliced["shots"]["104S"])
    extras = schema_extras(MaterialProperties)
    constants = {name for name, extra in extras.items() if SECTION not in extra and not extra.get(OPTIONAL)}
    assert constants | {"eos"} <= set(sliced["material"]) and "name" not in sliced["material"]
    law_specific = {name for name, extra in extras.items() if extra.get(OPTIONAL)}
    assert law_specific & set(config["material"]) and not law_specific & set(sliced["material"])   # Johnson-Cook's


def test_the_slice_is_a_copy(config):
    sliced = stage_config(config, "emulate")
    sliced["emulator"]["structure"] = "per_shot"
    assert config["emulator"]["structure"] == "joint"


def test_only_history_figures_read_the_seed(config):
    seeded = {name for name in catalogue(config) if "seed" in figure_config(config, name).get("study", {})}
    assert seeded == {"fig11_history_104S", "fig12_history_105S", "fig13_history_106S"}


def test_an_undeclared_or_misspelt_key_is_named(config):
    with pytest.raises(KeyError, match="calibration.n_lives"):
        config_slice(config, ["calibration.n_lives"], label="test")
    with pytest.raises(ValueError, match="needs a shot"):
        stage_config(config, "simulate")
    with pytest.raises(ValueError, match="unknown stage 'simulation'"):
        stage_config(config, "simulation")


@pytest.mark.parametrize("stage, check", [("calibrate", False), ("calibrate_check", True)])
def test_the_calibrations_read_the_discrepancy_from_their_slice(tmp_path, stage, check):
    """`shockcal calibrate` and `calibrate-check` read their stage's slice: `calibration.discrepancy` is in it (the
    posterior then samples the discrepancy's parameters), and a change of it reruns their jobs."""
    from shockcal.inference.settings import DiscrepancySettings
    from shockcal.study.adapters import calibration_settings
    from shockcal.study.stages import load_stage_config

    overlay = tmp_path / "discrepancy.yaml"
    overlay.write_text(f"extends: {REPO / 'config' / 'config.yaml'}\n"
                       "calibration: {discrepancy: {kind: feature_kind, sd_fraction_prior: 0.03}}\n")
    settings = calibration_settings(load_stage_config(overlay, stage), ["104S"], check=check)
    assert settings.discrepancy == DiscrepancySettings(kind="feature_kind", sd_fraction_prior=0.03)
    assert calibration_settings(load_stage_config(REPO / "config" / "config.yaml", stage), ["104S"],
                                check=check).discrepancy == "none"


@pytest.mark.parametrize(("source", "given", "left_out"), [
    ("records", {"records", "readout_error", "readout_replicates"}, "features"),
    ("published", {"features"}, "records"),
])
def test_the_observed_stage_reads_its_sources_keys_alone(config, source, given, left_out):
    """A change of the published values does not rerun a study measured from its records (and whatever
    depends on its observed table), nor the other way round; the velocity boxes of the plateau check only."""
    sliced = stage_config({**config, "observed": {**config["observed"], "source": source}}, "observed")
    assert given <= set(sliced["observed"]) and left_out not in sliced["observed"]
    assert ("features" in sliced) == (source == "records")     # the extractor's settings
    assert set(sliced["inputs"]) == {spec["velocity_input"] for spec in config["shots"].values()}


def test_a_candidates_stages_read_its_reference_shot_alone(config):
    """A candidate's design, runs and features read its reference shot's plates, moduli and window, not another
    shot's: a change of 106S's window reruns no candidate of 104S (the check's truths read every candidate's)."""
    study = {**config, "next_shot": {**config["next_shot"], "candidates": {
        "hot": {**next(iter(config["next_shot"]["candidates"].values())), "shot": "105S"}}}}
    for stage in ("next_shot_design", "next_shot_simulate", "next_shot_features"):
        sliced = stage_config(study, stage, "hot")
        assert set(sliced["shots"]) <= {"104S", "105S", "106S"} and all(
            spec == {} for shot, spec in sliced["shots"].items() if shot != "105S"), stage
        assert set(sliced["shots"]["105S"]) == {"flyer_mm", "target_mm", "shear_modulus_inputs", "analysis"}, stage
    truths = stage_config(study, "next_shot_check_truths")
    assert set(truths["shots"]) == {"105S"}
