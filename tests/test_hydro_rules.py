"""The library refuses what the config refuses: the hydrocode's inputs check their fields on construction
with the rules of shockcal.hydro.rules, which the config schema names (`x-rule`), in the same words."""

from __future__ import annotations

import copy

import numpy as np
import pytest

from shockcal.campaign.settings import CandidateShot
from shockcal.design.settings import InputRange
from shockcal.design.tables import InputBox
from shockcal.errors import ConfigError, InputError
from shockcal.hydro import Geometry, HydroSettings, LawShotParameters, MaterialProperties, ShotParameters
from shockcal.hydro.material_library import load_material
from shockcal.hydro.shot import run_shot
from shockcal.study.validate import validate_config

AL5083 = load_material("al5083")   # the paper's Al-5083, from the material library

JC_104S = dict(A_MPa=335.0, B_MPa=425.0, C=0.0335, n=0.42, m=1.225, shear_modulus_GPa=26.9)


@pytest.mark.parametrize("make, message", [
    (lambda: Geometry(flyer_mm=3.95, target_mm=-5.965, end_us=2.2), "Geometry.target_mm: -5.965 is not a positive number"),
    (lambda: Geometry(flyer_mm=3.95, target_mm=0.0, end_us=2.2), "Geometry.target_mm: 0 is not a positive number"),
    (lambda: Geometry(flyer_mm=np.nan, target_mm=5.965, end_us=2.2), "Geometry.flyer_mm: nan is not a positive number"),
    (lambda: Geometry(flyer_mm=3.95, target_mm=5.965, end_us=2.2, initial_temperature_K=-10.0),
     "Geometry.initial_temperature_K: -10 is not a positive number"),
    (lambda: ShotParameters(**JC_104S, velocity_m_s=-204), "ShotParameters.velocity_m_s: -204 is not a positive number"),
    (lambda: ShotParameters(**JC_104S, velocity_m_s=204000),
     "ShotParameters.velocity_m_s: 204000 is above 10000 m/s, faster than any plate-impact launcher"),
    (lambda: ShotParameters(**JC_104S, velocity_m_s=np.float64("inf")),
     "ShotParameters.velocity_m_s: inf is not a number in (0, 10000]"),
    (lambda: ShotParameters(**{**JC_104S, "A_MPa": -1.0}, velocity_m_s=204), "ShotParameters.A_MPa: -1 is negative"),
    (lambda: ShotParameters(**{**JC_104S, "shear_modulus_GPa": 0.0}, velocity_m_s=204),
     "ShotParameters.shear_modulus_GPa: 0 is not a positive number"),
    (lambda: LawShotParameters("jc", {"A_MPa": 335, "B_MPa": 425, "C": 0.0335, "n": 0.42, "m": 1.225}, 204000, 26.9),
     "LawShotParameters.velocity_m_s: 204000 is above 10000 m/s"),
    (lambda: HydroSettings(cell_size_um=0.0), "HydroSettings.cell_size_um: 0 is not a positive number"),
    (lambda: HydroSettings(cfl=1.5), "HydroSettings.cfl: 1.5 is above 1"),
    (lambda: HydroSettings().replace(cfl=1.5), "HydroSettings.cfl: 1.5 is above 1"),
    (lambda: HydroSettings(q_linear=-0.1), "HydroSettings.q_linear: -0.1 is negative"),
    (lambda: MaterialProperties(**{**AL5083.__dict__, "c1_Mbar": -0.78}), "MaterialProperties.c1_Mbar: -0.78 is not a positive"),
    (lambda: MaterialProperties(**{**AL5083.__dict__, "c3_Mbar": np.inf}), "MaterialProperties.c3_Mbar: inf is not a finite"),
])
def test_impossible_inputs_are_refused_on_construction_naming_the_field(make, message):
    with pytest.raises(InputError) as err:
        make()
    assert str(err.value).startswith(message)


def test_a_plate_thinner_than_one_cell_is_refused_before_the_run():
    """The cell count used to be rounded up to one: a 1 um target ran as a 4 um one and said "ok"."""
    params = ShotParameters(**JC_104S, velocity_m_s=204)
    with pytest.raises(InputError, match=r"Geometry.target_mm: 0.001 mm is thinner than one cell of the mesh "
                                         r"\(cell_size_um = 4 um\)"):
        run_shot(params, Geometry(flyer_mm=3.95, target_mm=0.001, end_us=0.1), AL5083)


FAST = {"flyer_mm": 3.95, "target_mm": 5.965, "velocity_m_s": 204}     # a next-shot candidate's plates and velocity


@pytest.mark.parametrize("section, key, value, library", [
    ("shots.104S", "target_mm", 0.0, lambda: Geometry(flyer_mm=3.95, target_mm=0.0, end_us=2.2)),
    ("shots.104S", "flyer_mm", -3.95, lambda: Geometry(flyer_mm=-3.95, target_mm=5.965, end_us=2.2)),
    ("shots.104S", "target_mm", 0.001, lambda: HydroSettings().cells(0.001, "Geometry.target_mm")),
    ("hydro", "cfl", 1.5, lambda: HydroSettings(cfl=1.5)),
    ("hydro", "q_quadratic", -1.0, lambda: HydroSettings(q_quadratic=-1.0)),
    ("material", "T_melt_K", float("nan"), lambda: MaterialProperties(**{**AL5083.__dict__, "T_melt_K": float("nan")})),
    ("material", "T_melt_K", 298.0, lambda: MaterialProperties(**{**AL5083.__dict__, "T_melt_K": 298.0})),
    ("material", "T_melt_K", 250.0, lambda: MaterialProperties(**{**AL5083.__dict__, "T_melt_K": 250.0})),
    ("next_shot.candidates.fast", "velocity_m_s", 204000, lambda: ShotParameters(**JC_104S, velocity_m_s=204000)),
    ("next_shot.candidates.fast", "velocity_m_s", -204, lambda: ShotParameters(**JC_104S, velocity_m_s=-204)),
    ("next_shot.candidates.fast", "velocity_m_s", 204000, lambda: CandidateShot(**{**FAST, "velocity_m_s": 204000})),
    ("next_shot.candidates.fast", "target_mm", 0.0, lambda: CandidateShot(**{**FAST, "target_mm": 0.0})),
    ("next_shot.candidates.fast", "initial_temperature_K", -10.0,
     lambda: CandidateShot(**FAST, initial_temperature_K=-10.0)),
    ("inputs.A", "min", 0.02, lambda: InputRange(min=0.02, max=0.01, unit="Mbar")),
    ("inputs.A", "min", 0.02, lambda: InputBox({"A": (0.02, 0.01)}, {"A": "Mbar"})),
])
def test_the_config_gives_the_librarys_message(paper_config, section, key, value, library):
    """One rule behind both doors: after its key, the config's message is the library's word for word."""
    config = copy.deepcopy(paper_config)
    config["next_shot"]["candidates"]["fast"] = {"shot": "104S", **FAST}
    node = config
    for part in section.split("."):
        node = node[part]
    node[key] = value
    with pytest.raises(ConfigError) as from_config:
        validate_config(config, source="config.yaml")
    with pytest.raises(InputError) as from_library:
        library()
    config_says = str(from_config.value).removeprefix(f"config.yaml: {section}.{key}: ")
    library_says = str(from_library.value).split(": ", 1)[1]
    assert config_says == library_says


def test_a_shots_velocity_box_obeys_the_impact_velocity_rule(paper_config):
    paper_config["inputs"]["V1"]["max"] = 20.4                          # cm/us: 204000 m/s
    with pytest.raises(ConfigError, match=r"inputs\.V1\.max: 20\.4 cm/us, shot 104S's impact velocity in m/s: "
                                          r"204000 is above 10000 m/s"):
        validate_config(paper_config)
