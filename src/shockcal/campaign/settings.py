"""The campaign's questions as settings models: which shot next (the study config's `next_shot` section, its
modulus slope and its realized check) and which inputs matter (`sensitivity`). Each field's default, limits
and description is here once; the config schema's entries are generated from them (`shockcal.settings_model`).
A candidate as the config gives it (`next_shot.candidates.<name>`) is a `CandidateShot`; with what the study gives
it, a `shockcal.campaign.candidates.Candidate`."""

from __future__ import annotations

from typing import Annotated

from pydantic import Field, ValidationInfo, field_validator
from pydantic_core import PydanticCustomError

from shockcal.hydro.settings import Plates
from shockcal.hydro.settings_model import setting as hydro_setting
from shockcal.inference.settings import MIN_N_EFF, MIN_N_LIVE
from shockcal.settings_model import SettingsModel, setting
from shockcal.velocimetry.columns import CALIBRATION_FEATURES

ReadoutSd = Annotated[float, Field(ge=0, description="The read-out error sd of this feature.")]


def is_power_of_two(n: int) -> bool:
    """Whether a Saltelli base sample `n` balances a Sobol sequence: a power of 2 (2, 4, 8, ...)."""
    return n >= 2 and not n & (n - 1)


class SensitivitySettings(SettingsModel):
    """The emulator's Sobol indices (`shockcal.campaign.sensitivity.emulator_sobol`, `shockcal sensitivity`)."""

    n_base: int = setting(1024, "Saltelli base sample, a power of 2: N (d + 2) emulator predictions per shot and "
                                "domain.", ge=64)
    resamples: int = setting(100, "Bootstrap resamples of the indices' 95% intervals.", ge=10)

    @field_validator("n_base")
    @classmethod
    def _a_power_of_two(cls, n_base: int) -> int:
        if not is_power_of_two(n_base):
            raise PydanticCustomError("power_of_two", "{n_base} is not a power of 2 (Sobol sequences balance only "
                                                      "then)", {"n_base": n_base})
        return n_base


class NextShotSettings(SettingsModel):
    """Which shot next (`shockcal suggest-shot`; docs/next_shot.md): how the candidates are scored, the study
    config's `next_shot` keys besides the candidates, `grid`, the modulus slope and the check."""

    targets: list[str] | None = setting(
        None, "The parameters of interest (inputs): the ranking's eig_nats is the information about them jointly; "
        "each also gets its own marginal gain and expected posterior sd. null: every parameter of the study's "
        "strength law (Johnson-Cook: A, B, C, n, m).", min_length=1)
    n_draws: int = setting(200, "Joint-posterior draws run through the hydrocode per candidate (the same draws for "
                                "every candidate).", ge=20)
    velocity_sd_fraction: float = setting(
        0.02, "Impact-velocity error of a new shot, as a fraction (SPEC: about 2%): each draw's velocity is the "
        "candidate's times a factor uniform in 1 +- sqrt(3) x this (this sd), a nuisance input.", ge=0, le=0.2)
    emulator_error: bool = setting(
        True, "Add the emulator's K-fold RMSE of the reference shot's features (emulator/cv_rmse.csv) to the "
        "measurement noise, in quadrature: the next calibration reads the shot through an emulator, whose error caps "
        "what it can learn. False: the hydrocode is the model (what the shot itself holds).")
    readout_sd_m_s: dict[str, ReadoutSd] = setting(
        {}, "The extractor's read-out error sd per calibration feature (v_elastic, v_plastic, v_slope1, v_slope2), "
        "added in quadrature to the 1% observation error. A candidate has no record yet: a feature left out takes its "
        "reference shot's `readout_sd_v_*` from the observed features (observed.readout_error; 0 in a table without "
        "it, e.g. the published features), the cautious stand-in; give 0 to leave a feature's read-out error out.")

    @field_validator("targets")
    @classmethod
    def _each_target_once(cls, targets: list[str] | None) -> list[str] | None:
        if targets is not None and len(set(targets)) != len(targets):
            raise PydanticCustomError("twice", "{targets} names a target twice", {"targets": targets})
        return targets

    @field_validator("readout_sd_m_s")
    @classmethod
    def _calibration_features(cls, readout: dict[str, float]) -> dict[str, float]:
        for feature in readout:
            if feature not in CALIBRATION_FEATURES:
                raise PydanticCustomError("feature", "{feature}: not a calibration feature {features}",
                                          {"feature": feature, "features": list(CALIBRATION_FEATURES)})
        return readout


class ModulusSlopeSettings(SettingsModel):
    """d ln G / dT of a hot candidate's shear modulus (`next_shot.shear_modulus_log_slope_per_K`): G(T0) = G_ref
    (1 + s (T0 - material.T_ref_K)), s uniform in [min, max] per draw (`shockcal.campaign.candidates`)."""

    min: float = setting(-7.5e-4, "Lowest slope.")
    max: float = setting(-2.5e-4, "Highest slope.")

    @field_validator("max")
    @classmethod
    def _not_below_min(cls, highest: float, info: ValidationInfo) -> float:
        lowest = info.data.get("min")
        if lowest is not None and highest < lowest:
            raise PydanticCustomError("order", "{highest} is below min ({lowest})",
                                      {"highest": f"{highest:g}", "lowest": f"{lowest:g}"})
        return highest


class NextShotCheckSettings(SettingsModel):
    """The realized check of the ranking (`make next-shot-check`; `shockcal.campaign.ranking_check`):
    `next_shot.check`."""

    candidates: list[str] | None = setting(
        None, "The two candidates compared (names of next_shot.candidates); null: the best and the worst of "
        "`<results>/next_shot/ranking.csv` by eig_nats.", min_length=2, max_length=2)
    n_truths: int = setting(10, "Truths drawn from the joint posterior (stream next_shot \"check_truths\"), each "
                                "calibrated three times.", ge=2)
    n_training_runs: int = setting(
        300, "Training runs of each compared candidate, at the first rows of the study's training design (in a "
        "sequential study, wave 0's Latin hypercube: at most design.waves.initial_runs); the check's emulators are "
        "fitted on these rows of every shot.", ge=10)
    n_live: int = setting(500, "Live points of each of the check's calibrations.", ge=MIN_N_LIVE)
    n_eff: int = setting(1000, "Effective sample size each of the check's calibrations runs to.", ge=MIN_N_EFF)

    @field_validator("candidates")
    @classmethod
    def _two_candidates(cls, candidates: list[str] | None) -> list[str] | None:
        if candidates is not None and candidates[0] == candidates[1]:
            raise PydanticCustomError("same", "compares {name} with itself; name two candidates",
                                      {"name": candidates[0]})
        return candidates


class CandidateShot(Plates):
    """A next-shot candidate as the config gives it (`next_shot.candidates.<name>`, the schema's `candidate`
    entry, generated from these fields): a shot's plates (`Plates`, hot thicknesses when heated) and its nominal
    impact velocity. Checked on creation: a SettingsError naming the class and the field."""

    velocity_m_s: float = hydro_setting(..., "Nominal impact velocity.", "impact_velocity_m_s")
