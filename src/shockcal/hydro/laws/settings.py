"""The strength law a study calibrates: the study config's `strength` keys besides the law's own prior box, as a
settings model (its fields' defaults and descriptions once; the config schema's entries are generated from it,
`shockcal.settings_model`). The laws it names are the registry's (`shockcal.hydro.laws.declarations.LAWS`)."""

from __future__ import annotations

from typing import Literal

from shockcal.hydro.laws.declarations import DEFAULT_MODEL, LAWS
from shockcal.settings_model import SettingsModel, setting

LawName = Literal[tuple(LAWS)]


class StrengthSettings(SettingsModel):
    """Which law (`shockcal.hydro.laws.get_law`) and where its literature prior boxes are."""

    model: LawName = setting(
        DEFAULT_MODEL, "The law. Another than johnson-cook calibrates its declared parameters (design columns named as "
        "in src/shockcal/hydro/laws/declarations.py, unit in the name) plus each shot's impact velocity, and each "
        "shot's shear-modulus inputs only for a law without a G law of its own (zerilli-armstrong); steinberg-guinan "
        "and ptw compute G(P, T) from their G0_GPa. The Johnson-Cook inputs A, B, C, n, m of `inputs`, and the names "
        "of `calibration.cube_power` that are Johnson-Cook's and not the law's, are then ignored.")
    models_file: str = setting(
        "config/models.yaml", "The literature prior boxes per law (low, high, with sources), relative to the working "
        "directory; a law parameter without a default that `strength.inputs` leaves out takes its box from here.")
