"""`study.reference_sets` (shockcal.study.references) and `study.report_notes`: what the posterior figures draw,
the one-line refusals; `calibration.cube_power` under another law."""

from __future__ import annotations

import copy

import pytest

from shockcal.errors import ConfigError
from shockcal.study.references import drawn_sets, outside_box
from shockcal.study.validate import validate_config

GRAY_ALL = {"A_MPa": 210.0, "B_MPa": 620.0, "C": 0.0125, "n": 0.375, "m": 1.525}


def _with_sets(config: dict, sets: list[dict]) -> dict:
    config = copy.deepcopy(config)
    config["study"]["reference_sets"] = sets
    return config


def test_the_papers_sets_are_drawn_on_its_inputs_in_their_units(paper_config_readonly):
    sets = drawn_sets(paper_config_readonly)
    assert [s.label for s in sets] == ["Gray et al.: all rates, all T", "Gray et al.: high rate, all T",
                                       "Gray et al.: all rates, T > RT", "Gray et al.: high rate, T > RT"]
    assert sets[0].values == {"A": (210.0, "MPa"), "B": (620.0, "MPa"), "C": (0.0125, "-"), "n": (0.375, "-"),
                              "m": (1.525, "-")}
    assert sets[0].citation.startswith("Gray et al.")


def test_no_key_no_sets(paper_config_readonly):
    config = copy.deepcopy(paper_config_readonly)
    del config["study"]["reference_sets"]
    assert drawn_sets(config) == [] and outside_box(config) == []


def test_a_value_outside_the_box_is_named_not_refused(paper_config_readonly):
    """Gray's C = 0.0335 lies above the paper's box [0, 0.03]: drawn, and named with the box."""
    assert outside_box(paper_config_readonly) == [
        "study.reference_sets 'Gray et al.: high rate, T > RT': C = 0.0335 is outside the prior box [0, 0.03]"]
    config = _with_sets(paper_config_readonly, [{"label": "high A", "values": {"A_MPa": 2000.0}}])
    assert outside_box(validate_config(config, "c.yaml")) == [
        "study.reference_sets 'high A': A = 2000 MPa is outside the prior box [50, 1000] MPa"]


@pytest.mark.parametrize("sets, message", [
    ([{"label": "x", "values": {"A": 210.0}}],
     r"^c\.yaml: study\.reference_sets\[0\]\.values\.A: not a parameter of johnson-cook \(parameters: A_MPa, "),
    ([{"label": "x", "values": GRAY_ALL}, {"label": "x", "values": GRAY_ALL}],
     r"^c\.yaml: study\.reference_sets\[1\]\.label: 'x' is the label of an earlier set$"),
    ([{"label": "x", "model": "ptw", "values": {"Y0_GPa": 0.2}}],
     r"^c\.yaml: study\.reference_sets\[0\]\.values\.Y0_GPa: not a parameter of ptw "),
    ([{"label": "x", "values": {}}], r"^c\.yaml: study\.reference_sets\.0\.values: .*"),
])
def test_a_wrong_set_is_one_line(paper_config_readonly, sets, message):
    with pytest.raises(ConfigError, match=message) as err:
        validate_config(_with_sets(paper_config_readonly, sets), "c.yaml")
    assert "\n" not in str(err.value)


def test_a_set_of_another_law_is_not_drawn(paper_config_readonly):
    """Under Steinberg-Guinan the Johnson-Cook sets are not drawn, its own are, on its declared names."""
    config = _with_sets(paper_config_readonly, [
        *paper_config_readonly["study"]["reference_sets"],
        {"label": "SG fit", "model": "steinberg-guinan", "values": {"Y0_GPa": 0.3, "n": 0.1, "T_m0_K": 1220.0}}])
    config["strength"] = {"model": "steinberg-guinan"}
    sets = drawn_sets(validate_config(config, "c.yaml"))
    assert [(s.label, s.values) for s in sets] == [("SG fit", {"Y0_GPa": (0.3, "GPa"), "n": (0.1, "-")})]
    assert drawn_sets(validate_config(_with_sets(paper_config_readonly, sets=[
        {"label": "SG fit", "model": "steinberg-guinan", "values": {"Y0_GPa": 0.3}}]), "c.yaml")) == []


def test_a_note_for_an_unknown_caption_is_one_line(paper_config_readonly):
    config = copy.deepcopy(paper_config_readonly)
    config["study"]["report_notes"] = {"fig07_marginal": "typo"}
    with pytest.raises(ConfigError, match=r"^c\.yaml: study\.report_notes\.fig07_marginal: no caption of that "
                                          r"name; captions: fig01_toy_calibration, "):
        validate_config(config, "c.yaml")


def test_another_law_keeps_the_cube_power_of_its_own_parameter(paper_config_readonly):
    """Steinberg-Guinan has an n: a power given for it stays; Johnson-Cook's m (inherited) is dropped; a name
    of neither is refused."""
    config = copy.deepcopy(paper_config_readonly)
    config["strength"] = {"model": "steinberg-guinan"}
    config["calibration"]["cube_power"] = {"m": 2, "n": 3}
    assert validate_config(copy.deepcopy(config), "c.yaml")["calibration"]["cube_power"] == {"n": 3}
    config["calibration"]["cube_power"] = {"Y0": 2}
    with pytest.raises(ConfigError, match=r"^c\.yaml: calibration\.cube_power\.Y0: not one of the inputs"):
        validate_config(config, "c.yaml")
