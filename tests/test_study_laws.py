"""The study under any strength law (config `strength`): the effective box, the shots' mappings, the
emulator's inputs, and bad input stopped with one line naming the key before any run."""

from __future__ import annotations

import copy

import numpy as np
import pytest
import yaml

from shockcal.errors import ConfigError
from shockcal.hydro import LawShotParameters, ShotParameters
from shockcal.study.adapters import emulator_spec, shot_mapping, study_design
from shockcal.study.stages import stage_config
from shockcal.study.strength_config import next_shot_targets
from shockcal.study.validate import validate_config


def _with_model(config: dict, model: str, **strength) -> dict:
    config = copy.deepcopy(config)
    config["strength"] = {"model": model, **strength}
    return validate_config(config, "test.yaml")


def test_johnson_cook_config_is_unchanged(paper_config):
    """Left out or given as johnson-cook, the strength section changes neither the box nor the design, and a
    config without it slices no `strength` key into any stage (no job reruns)."""
    explicit = _with_model(paper_config, "johnson-cook")
    assert explicit["inputs"] == paper_config["inputs"]
    a, _ = study_design(paper_config, n_runs=50)
    b, _ = study_design(explicit, n_runs=50)
    assert a.equals(b)
    for stage in ("design", "simulate", "emulate", "calibrate"):
        assert "strength" not in stage_config(paper_config, stage, "104S")
    assert "strength" in stage_config(explicit, "simulate", "104S")
    assert isinstance(shot_mapping(paper_config, "105S").parameters(a.iloc[0]), ShotParameters)


def test_steinberg_guinan_box_and_mappings(paper_config):
    """SG: its seven calibrated parameters (models.yaml, declared units) and the three velocities; no
    G1/Delta inputs (G(P, T) is the law's); no eps^n, T*^m emulator inputs; JC's cube power dropped."""
    config = _with_model(paper_config, "steinberg-guinan")
    assert list(config["inputs"]) == ["Y0_GPa", "Ymax_GPa", "beta", "n", "G0_GPa", "dGdP", "dGdT_over_G0_per_K",
                                      "V1", "V2", "V3"]
    assert config["inputs"]["Y0_GPa"] == {"min": 0.10, "max": 0.45, "unit": "GPa"}
    assert config["calibration"]["cube_power"] == {}
    assert next_shot_targets(config) == list(config["inputs"])[:7]   # the next shot's default: the law's
    mapping = shot_mapping(config, "106S")
    assert mapping.shear_modulus_inputs == () and mapping.inputs()[-1] == "V3"
    design, _ = study_design(config, n_runs=8)
    params = mapping.parameters(design.iloc[0])
    assert isinstance(params, LawShotParameters) and params.shear_modulus_GPa is None
    assert params.velocity_m_s == pytest.approx(design["V3"].iloc[0] * 1e4, rel=1e-15)
    spec = emulator_spec(config, ["104S", "105S", "106S"])
    assert spec.powers == ()
    assert validate_config(copy.deepcopy(config), "again.yaml")["inputs"] == config["inputs"]   # idempotent


def test_zerilli_armstrong_keeps_the_shots_moduli(paper_config):
    config = _with_model(paper_config, "zerilli-armstrong")
    assert list(config["inputs"])[:4] == ["C0_MPa", "C2_MPa", "C3_per_K", "C4_per_K"]
    assert shot_mapping(config, "106S").shear_modulus_inputs == ("G1", "Delta2", "Delta3")
    design, _ = study_design(config, n_runs=4)
    row = design.iloc[1]
    params = shot_mapping(config, "106S").parameters(row)
    assert params.shear_modulus_GPa == pytest.approx(100 * (row["G1"] + row["Delta2"] + row["Delta3"]), rel=1e-14)


def test_strength_inputs_override_the_models_file(paper_config):
    config = _with_model(paper_config, "zerilli-armstrong", inputs={"C0_MPa": {"min": 100.0, "max": 350.0}})
    assert config["inputs"]["C0_MPa"] == {"min": 100.0, "max": 350.0, "unit": "MPa"}


@pytest.mark.parametrize("strength, message", [
    ({"model": "voce"}, "strength.model: 'voce' is not one of"),
    ({"model": "steinberg-guinan", "inputs": {"A_MPa": {"min": 1, "max": 2}}},
     "strength.inputs.A_MPa: not a parameter of steinberg-guinan"),
    ({"model": "steinberg-guinan", "inputs": {"Y0_GPa": {"min": 0.3}}}, "strength.inputs.Y0_GPa: 'max' is a required property"),
    ({"model": "steinberg-guinan", "inputs": {"n": {"min": 0.5, "max": 0.1}}}, r"strength.inputs.n.min: 0.5 is not below max \(0.1\)"),
    ({"model": "steinberg-guinan", "inputs": {"Ymax_GPa": {"min": 0.2, "max": 1.0}}}, "breaks the law .*Ymax_GPa >= Y0_GPa"),
    ({"model": "zerilli-armstrong", "inputs": {"C0_MPa": {"min": -50.0, "max": 300.0}}},
     "flow stress is -50 MPa at the box corner C0_MPa=-50"),
    ({"model": "ptw", "inputs": {"gamma": {"min": 0.0, "max": 0.1}}}, "breaks the law"),
])
def test_bad_strength_section_is_one_line(paper_config, strength, message):
    config = copy.deepcopy(paper_config)
    config["strength"] = strength
    with pytest.raises(ConfigError, match=message) as caught:
        validate_config(config, "test.yaml")
    assert "\n" not in str(caught.value)


def test_missing_bound_names_the_parameter(paper_config, tmp_path):
    boxes = yaml.safe_load(open("config/models.yaml"))
    del boxes["steinberg-guinan"]["parameters"]["beta"]
    path = tmp_path / "models.yaml"
    path.write_text(yaml.safe_dump(boxes))
    with pytest.raises(ConfigError, match="strength.inputs.beta: missing; steinberg-guinan needs a box"):
        _with_model(paper_config, "steinberg-guinan", models_file=str(path))


def test_an_input_neither_the_laws_nor_a_shots_is_an_error(paper_config):
    config = copy.deepcopy(paper_config)
    config["inputs"]["Y0_GPa"] = {"min": 0.1, "max": 0.4, "unit": "GPa"}
    config["strength"] = {"model": "steinberg-guinan"}
    with pytest.raises(ConfigError, match="inputs.Y0_GPa: a steinberg-guinan parameter; give its box as strength.inputs"):
        validate_config(config, "test.yaml")
    config = copy.deepcopy(paper_config)
    config["inputs"]["K1"] = {"min": 0.1, "max": 0.4, "unit": "Mbar"}
    config["strength"] = {"model": "zerilli-armstrong"}
    with pytest.raises(ConfigError, match="inputs.K1: neither a zerilli-armstrong parameter"):
        validate_config(config, "test.yaml")


@pytest.mark.parametrize("model", ["steinberg-guinan", "ptw", "zerilli-armstrong"])
def test_every_design_row_of_the_literature_box_runs(paper_config, model):
    """The models.yaml boxes meet each law's constraints at every point: 200 hypercube rows all make
    valid hydrocode inputs (the corner check's promise)."""
    config = _with_model(paper_config, model)
    design, _ = study_design(config, n_runs=200)
    mapping = shot_mapping(config, "104S")
    for _, row in design.iterrows():
        mapping.parameters(row)
    assert np.isfinite(design.drop(columns="run").to_numpy()).all()


def test_every_law_reads_its_study_inputs_from_its_declaration(paper_config):
    """Johnson-Cook is one registry entry: its study inputs are its declared fields (code-unit columns), the
    emulator's eps^n and T*^m come from the roles it declares, and a next-shot candidate's box and split check
    read the study's law (another law's candidate box holds its own inputs; its split check names the roles
    it lacks)."""
    from shockcal.campaign.candidates import check_split
    from shockcal.errors import InputError
    from shockcal.hydro.laws import get_law
    from shockcal.study.adapters import candidate, candidate_box, material_properties

    law = get_law("johnson-cook")
    assert law.calibrated_columns() == ["A", "B", "C", "n", "m"]
    assert (law.role_column("hardening_exponent"), law.role_column("thermal_exponent")) == ("n", "m")
    section = paper_config["emulator"]
    assert emulator_spec(paper_config, ["104S"]).powers == ((section["hardening_strain"], "n"),
                                                            (section["homologous_temperature"], "m"))
    name = next(iter(paper_config["next_shot"]["candidates"]))
    assert list(candidate_box(paper_config, name).bounds)[:5] == ["A", "B", "C", "n", "m"]
    config = _with_model(paper_config, "zerilli-armstrong")
    box = candidate_box(config, name)
    assert list(box.bounds)[:4] == ["C0_MPa", "C2_MPa", "C3_per_K", "C4_per_K"]
    shot = candidate(config, name)
    assert shot.mapping().model == "zerilli-armstrong" and shot.mapping().strength_inputs[0] == "C0_MPa"
    with pytest.raises(InputError, match="zerilli-armstrong declares no yield_stress, rate_coefficient, thermal_exponent"):
        check_split(study_design(config, n_runs=2)[0], shot, material_properties(config), "here")
