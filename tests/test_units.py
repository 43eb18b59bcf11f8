"""The units a user reads: which unit for a declared one, the factor to it, the name that carries it, and
each study input's user unit from its declared unit and its role (a shot's shear-modulus input)."""

from __future__ import annotations

import pytest

from shockcal.study.config import input_columns, input_user_units
from shockcal.study.strength_config import apply_strength_model
from shockcal.units import unit_factor, unit_name, user_columns, user_unit


def test_user_unit_factor_and_name():
    assert [user_unit(u) for u in ("Mbar", "kbar", "cm/us", "km/s", "MPa", "GPa", "m/s", "K", "-")] == \
        ["MPa", "MPa", "m/s", "m/s", "MPa", "GPa", "m/s", "K", "-"]
    assert user_unit("Mbar", modulus=True) == "GPa" and user_unit(" GPa ", modulus=True) == "GPa"
    assert unit_factor("Mbar", "MPa") == 1e5 and unit_factor("Mbar", "GPa") == 100.0
    assert unit_factor("cm/us", "m/s") == 1e4 and unit_factor("kbar", "GPa") == 0.1 and unit_factor("K", "K") == 1.0
    with pytest.raises(ValueError, match="no factor from 'Mbar' to 'm/s'"):
        unit_factor("Mbar", "m/s")
    assert [unit_name(n, u) for n, u in (("A", "MPa"), ("V1", "m/s"), ("C", "-"), ("Y0_GPa", "GPa"),
                                         ("C3_per_K", "1/K"), ("x", "J/kg"))] == \
        ["A_MPa", "V1_m_s", "C", "Y0_GPa", "C3_per_K", "x_J_kg"]
    assert user_columns({"A": "Mbar", "n": "-"}, {"A": "MPa"}) == {"A": ("A_MPa", "MPa", 1e5), "n": ("n", "-", 1.0)}


def test_each_input_reads_in_the_unit_its_declaration_and_role_give(paper_config):
    assert input_user_units(paper_config) == {"A": "MPa", "B": "MPa", "C": "-", "n": "-", "m": "-", "V1": "m/s",
                                              "V2": "m/s", "V3": "m/s", "G1": "GPa", "Delta2": "GPa", "Delta3": "GPa"}
    assert input_columns(paper_config)["Delta3"] == ("Delta3_GPa", "GPa", 100.0)
    paper_config["inputs"]["A"]["unit"] = "MPa"                 # a box given in MPa stays in MPa, named A_MPa
    assert input_columns(paper_config)["A"] == ("A_MPa", "MPa", 1.0)
    paper_config["strength"] = {"model": "steinberg-guinan"}     # another law: its names carry their units
    apply_strength_model(paper_config, "config")
    columns = input_columns(paper_config)
    assert columns["Y0_GPa"] == ("Y0_GPa", "GPa", 1.0) and columns["V1"] == ("V1_m_s", "m/s", 1e4)
    assert "G1" not in columns                                   # its G law replaces the modulus inputs
