"""A strength law's material constants (PTW's molar mass, density and melt temperature, Steinberg-Guinan's
melt law, Johnson-Cook's reference and melt temperatures) come from the study's material through one
function (`shockcal.hydro.laws.law_values`), at both doors: the library's (`run_shot`'s material, the
`flow-stress` command's --material) and the study config's (`material`). An explicit value overrides the
material; a constant that neither gives stops in one line naming the material key; Al-5083 gives the
numbers the laws' declarations carried before."""

from __future__ import annotations

import copy

import pytest

from shockcal.cli import main
from shockcal.errors import ConfigError, InputError
from shockcal.hydro import LawShotParameters
from shockcal.hydro.laws import code_parameters, get_law, law_values
from shockcal.hydro.material_library import load_material
from shockcal.study.adapters import emulator_spec
from shockcal.study.stages import stage_config
from shockcal.study.strength_config import material_constants
from shockcal.study.validate import validate_config

PTW = dict(theta=0.02, p=2.0, s0=0.0080, sinf=0.0070, kappa=0.3, gamma=1e-3, y0=0.0056, yinf=0.0052, y1=0.02,
           y2=0.4, beta=0.25, G0_GPa=45.0, alpha=0.23)
SG = {"Y0_GPa": 0.12, "Ymax_GPa": 0.64, "beta": 36.0, "n": 0.45, "G0_GPa": 47.7, "dGdP": 1.35,
      "dGdT_over_G0_per_K": -3.96e-4}
# the values the laws' declarations carried before they moved to the material library's al5083
AL5083_BEFORE = {"ptw": {"M": 26.9815, "rho0": 2.668, "T_melt": 893.0},
                 "steinberg-guinan": {"T_m0": 1220.0, "gamma0": 1.97, "a": 1.5},
                 "johnson-cook": {"T_ref": 298.0, "T_melt": 893.0, "rate_ref": 1.0e-6}}


def _study(config: dict, model: str, material: dict) -> dict:
    config = copy.deepcopy(config)
    config["strength"] = {"model": model}
    config["material"] = material
    return validate_config(config, "study.yaml")


def test_a_copper_ptw_run_reads_coppers_constants():
    """Molar mass, density and melt temperature are copper's (63.546 g/mol, 8.93 g/cc, 1356 K), not aluminium's."""
    code = LawShotParameters("ptw", PTW, 300.0).law_parameters(load_material("copper"))
    assert (code.M, code.rho0, code.T_melt) == (63.546, 8.93, 1356.0)


def test_an_explicit_value_overrides_the_material():
    code = code_parameters(get_law("ptw"), {**PTW, "T_melt_K": 1300.0}, load_material("copper"))
    assert (code.M, code.T_melt) == (63.546, 1300.0)
    sg = code_parameters(get_law("sg"), {**SG, "gamma0": 2.02, "a": 1.5}, load_material("copper"))
    assert (sg.T_m0, sg.gamma0, sg.a) == (1790.0, 2.02, 1.5)         # T_m0 copper's, the other two given


@pytest.mark.parametrize("model", list(AL5083_BEFORE))
def test_al5083_gives_the_numbers_the_declarations_carried(model):
    values = {"ptw": PTW, "steinberg-guinan": SG,
              "johnson-cook": dict(A_MPa=170.0, B_MPa=425.0, C=0.0335, n=0.42, m=1.225)}[model]
    code = code_parameters(get_law(model), values, load_material("al5083"))
    assert {field: getattr(code, field) for field in AL5083_BEFORE[model]} == AL5083_BEFORE[model]


@pytest.mark.parametrize("model, material, key", [
    ("ptw", "ti6al4v", "material.molar_mass_g_per_mol"),
    ("sg", "copper", "material.melt_gamma0"),
    ("sg", "tantalum", "material.melt_T_m0_K"),
])
def test_a_constant_the_material_lacks_is_one_line_naming_the_key(model, material, key):
    values = PTW if model == "ptw" else SG
    with pytest.raises(InputError) as caught:
        LawShotParameters(model, values, 300.0).law_parameters(load_material(material))
    assert str(caught.value).startswith(f"{key}: missing") and "\n" not in str(caught.value)
    with pytest.raises(InputError, match=r"^material\.\w+: missing"):      # no material: the first constant
        law_values(get_law(model), values, None)


def test_the_flow_stress_command_takes_the_material(capsys):
    ptw = [f"--param={k}={v}" for k, v in PTW.items()]
    state = ["--strain-rate", "1e5", "--temperature", "300", "--points", "2"]
    assert main(["flow-stress", "--model", "ptw", *ptw, "--material", "ti6al4v", *state]) == 2
    err = capsys.readouterr().err
    assert "material.molar_mass_g_per_mol: missing" in err and len(err.strip().splitlines()) == 1
    assert main(["flow-stress", "--model", "ptw", *ptw, "--material", "copper", *state]) == 0
    copper = capsys.readouterr().out.splitlines()[-1]
    assert main(["flow-stress", "--model", "ptw", *ptw, "--param", "M_g_per_mol=26.9815", "--param",
                 "rho0_g_per_cc=2.668", "--material", "copper", *state]) == 0
    assert capsys.readouterr().out.splitlines()[-1] != copper      # PTW's rate scale reads M and rho0


def test_a_copper_study_reads_coppers_constants_at_every_stage(paper_config):
    """The config door: the box check, the simulate slice and the emulator's yield input all see copper's."""
    study = _study(paper_config, "ptw", {"name": "copper"})
    expected = {"M_g_per_mol": 63.546, "rho0_g_per_cc": 8.93, "T_melt_K": 1356.0}
    assert material_constants(study, "ptw") == expected
    assert emulator_spec(study, ["104S"]).yield_input.constants == expected
    assert stage_config(study, "simulate", "104S")["material"]["molar_mass_g_per_mol"] == 63.546


def test_a_study_whose_material_lacks_a_constant_stops_in_one_line(paper_config):
    with pytest.raises(ConfigError) as caught:
        _study(paper_config, "steinberg-guinan", {"name": "copper"})
    assert str(caught.value).startswith("study.yaml: material.melt_gamma0: missing") and "\n" not in str(caught.value)
    study = _study(paper_config, "steinberg-guinan", {"name": "copper", "melt_gamma0": 2.02, "melt_a": 1.5})
    assert material_constants(study, "steinberg-guinan") == {"T_m0_K": 1790.0, "gamma0": 2.02, "a": 1.5}


def test_a_boxed_material_constant_is_calibrated_not_read(paper_config):
    """strength.inputs boxing T_melt_K makes it an input: the material's value is neither used nor sliced."""
    config = copy.deepcopy(paper_config)
    config["strength"] = {"model": "ptw", "inputs": {"T_melt_K": {"min": 850.0, "max": 950.0}}}
    study = validate_config(config, "study.yaml")
    assert "T_melt_K" in study["inputs"] and "T_melt_K" not in material_constants(study, "ptw", study["inputs"])
    assert stage_config(study, "simulate", "104S")["material"]["molar_mass_g_per_mol"] == 26.9815
